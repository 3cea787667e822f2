#!/usr/bin/env bash
# Regenerate the tables of README.md's "Which representation?" section from zhc's own choice
# sections: `zhc audit` on the sample maps (without and with --require nonnegative) and `zhc demo`
# (the "## Choice" section of the Markdown each writes). The tables sit between the two marker
# comments; everything else in README.md is left as it is.
#
# Usage: scripts/readme_choice.sh [--check] [ZHC] [MAPS]
#   ZHC   the zhc binary (default build/cli/zhc)
#   MAPS  the sample maps' folder (default ../shared/data/envmaps, as the README's examples)
#   --check  change nothing; exit 1 (and show the difference) when README.md's tables are not what
#            the commands print now.
set -euo pipefail
cd "$(dirname "$0")/.."
check=0
if [ "${1:-}" = "--check" ]; then
    check=1
    shift
fi
zhc="${1:-build/cli/zhc}"
maps="${2:-../shared/data/envmaps}"
[ -x "$zhc" ] || { echo "readme_choice.sh: $zhc: not an executable (build it: cmake --build build --target zhc)" >&2; exit 2; }
[ -d "$maps" ] || { echo "readme_choice.sh: $maps: no such folder (bash scripts/fetch_envmaps.sh)" >&2; exit 2; }
zhc="$(cd "$(dirname "$zhc")" && pwd)/$(basename "$zhc")"
begin='<!-- readme_choice.sh: begin (generated: edit scripts/readme_choice.sh, not these lines) -->'
end='<!-- readme_choice.sh: end -->'
grep -qxF "$begin" README.md && grep -qxF "$end" README.md ||
    { echo "readme_choice.sh: README.md has no marker lines $begin / $end" >&2; exit 2; }

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# The tables (and any "none" notes) of a Markdown file's "## Choice" section.
choice_tables() { awk '/^## Choice$/ { on = 1; next } /^## / { on = 0 } on && /^(\| |- )/' "$1"; }
nmaps=$(find "$maps" -maxdepth 1 \( -name '*.exr' -o -name '*.hdr' \) | wc -l)

"$zhc" audit "$maps" --no-timing --markdown "$work/audit.md" > /dev/null
"$zhc" audit "$maps" --no-timing --require nonnegative --markdown "$work/audit_nonneg.md" > /dev/null
# The demo from inside the work folder, so that the paths it prints are the README's zhc-demo/.
(cd "$work" && "$zhc" demo -o zhc-demo > /dev/null)
{
    echo "$begin"
    echo "**The $nmaps sample maps** (mean relative rmse over the maps):"
    echo
    choice_tables "$work/audit.md"
    echo
    echo "Command: \`zhc audit ../shared/data/envmaps --no-timing --markdown audit.md\` (the \"Choice\" section of audit.md)."
    echo
    echo "**The $nmaps sample maps, non-negative only** (\`negative_fraction\` 0 on every map):"
    echo
    choice_tables "$work/audit_nonneg.md"
    echo
    echo "Command: \`zhc audit ../shared/data/envmaps --no-timing --require nonnegative --markdown audit.md\`."
    echo
    echo "**The demo scene** (its 256 baked probes; the reference is the baked SH3, so \`sh3\` is exact by construction):"
    echo
    choice_tables "$work/zhc-demo/audit.md"
    echo
    grep '^Embedded: ' "$work/zhc-demo/audit.md"
    echo
    echo "Command: \`zhc demo\` (the \"Choice\" section of zhc-demo/audit.md)."
    echo "$end"
} > "$work/block.md"
awk -v begin="$begin" -v end="$end" -v block="$work/block.md" '
    $0 == begin { while ((getline line < block) > 0) print line; skip = 1; next }
    $0 == end { skip = 0; next }
    !skip' README.md > "$work/README.md"
if [ "$check" = 1 ]; then
    if ! diff -u README.md "$work/README.md"; then
        echo "readme_choice.sh: README.md's choice tables are stale: run bash scripts/readme_choice.sh" >&2
        exit 1
    fi
    echo "readme_choice.sh: README.md's choice tables are current"
else
    cp "$work/README.md" README.md
    echo "readme_choice.sh: README.md's choice tables regenerated"
fi
