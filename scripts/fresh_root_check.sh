#!/usr/bin/env bash
# Runs the README's two set-up commands in a fresh Debian 12 minbase root, from a clean clone of
# this repository's HEAD, as a new user's machine would: nothing installed but what
# `debootstrap --variant=minbase bookworm` gives, no ../shared beside the clone (the sample maps come
# from Debian's blender-data package). Run it as root before every release-like change:
#
#   bash scripts/fresh_root_check.sh [--runs N] [--keep] [ROOT]
#
#   --runs N   run the test command N times in a row (default 1), each from the same root
#   --keep     keep ROOT afterwards (default: removed)
#   ROOT       where the root is made (default: a new folder under /var/tmp)
#
# Needs: root, debootstrap (apt-get install debootstrap), about 6 GB of disk. The root gets the
# host's apt sources and apt settings (so a mirror or proxy the host uses works there too) and
# /etc/resolv.conf; NODE_EXTRA_CA_CERTS, when set, is passed on with its file. Prints the time of
# each command, keeps each command's log in a folder under /var/tmp, and exits non-zero when any fails.
set -euo pipefail
runs=1 keep=0 root=""
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) runs=$2; shift 2 ;;
    --keep) keep=1; shift ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    *) root=$1; shift ;;
  esac
done
[ "$(id -u)" -eq 0 ] || { echo "fresh_root_check: must run as root (debootstrap, chroot, mount)" >&2; exit 2; }
command -v debootstrap >/dev/null || { echo "fresh_root_check: debootstrap missing (apt-get install debootstrap)" >&2; exit 2; }
repo=$(cd "$(dirname "$0")/.." && pwd)
[ -n "$root" ] || root=$(mktemp -d /var/tmp/zhc-fresh-root.XXXXXX)
mkdir -p "$root"
chmod 755 "$root"  # the root's "/": mktemp makes it 0700, which no machine's / is (tests run zhc as nobody)
logs=$(mktemp -d /var/tmp/zhc-fresh-logs.XXXXXX)
echo "fresh_root_check: logs in $logs"

mounted=()
cleanup() {
  for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do umount -l "${mounted[$i]}" 2>/dev/null || true; done
  if [ "$keep" -eq 0 ]; then rm -rf --one-file-system "$root"; else echo "fresh_root_check: root kept in $root"; fi
}
trap cleanup EXIT

mirror=$(grep -h -m1 -oE '^(URIs:|deb) *https?://[^ ]+' /etc/apt/sources.list /etc/apt/sources.list.d/*.sources 2>/dev/null |
         head -1 | grep -oE 'https?://[^ ]+' || true)
[ -n "$mirror" ] || mirror=http://deb.debian.org/debian
echo "fresh_root_check: debootstrap --variant=minbase bookworm $root ($mirror)"
t0=$(date +%s)
debootstrap --variant=minbase bookworm "$root" "$mirror" >"$logs/debootstrap.log" 2>&1 ||
  { tail -20 "$logs/debootstrap.log" >&2; exit 1; }
echo "fresh_root_check: root made in $(( $(date +%s) - t0 )) s"

# The host's package sources and settings (mirrors, snapshot validity), name resolution, npm config.
rm -rf "$root/etc/apt/sources.list.d"
cp -a /etc/apt/sources.list.d "$root/etc/apt/"
[ -f /etc/apt/sources.list ] && cp /etc/apt/sources.list "$root/etc/apt/" || rm -f "$root/etc/apt/sources.list"
cp -a /etc/apt/apt.conf.d/. "$root/etc/apt/apt.conf.d/"
cp -L /etc/resolv.conf "$root/etc/resolv.conf"
[ -f "$HOME/.npmrc" ] && cp "$HOME/.npmrc" "$root/root/.npmrc"
env_pass=()
if [ -n "${NODE_EXTRA_CA_CERTS:-}" ] && [ -f "$NODE_EXTRA_CA_CERTS" ]; then
  mkdir -p "$root/opt/zhc-host-ca" && cp "$NODE_EXTRA_CA_CERTS" "$root/opt/zhc-host-ca/ca.crt"
  env_pass+=(NODE_EXTRA_CA_CERTS=/opt/zhc-host-ca/ca.crt)
fi

for m in proc sys dev dev/pts; do
  mkdir -p "$root/$m"
  case $m in
    proc) mount -t proc proc "$root/proc" ;;
    *) mount --bind "/$m" "$root/$m" ;;
  esac
  mounted+=("$root/$m")
done
mkdir -p "$root/dev/shm" && mount -t tmpfs -o size=2g tmpfs "$root/dev/shm" && mounted+=("$root/dev/shm")

# A clean clone of HEAD (what is committed, nothing else), with no ../shared beside it.
mkdir -p "$root/work"
git clone -q --no-hardlinks "$repo" "$root/work/zhc"
git -C "$root/work/zhc" checkout -q "$(git -C "$repo" rev-parse HEAD)"

in_root() {
  chroot "$root" /usr/bin/env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    LANG=C.UTF-8 CI=true "${env_pass[@]}" bash -c "cd /work/zhc && $1"
}
status=0
t=$(date +%s)
if in_root "bash scripts/run.sh -o /tmp/demo" >"$logs/run.log" 2>&1; then
  echo "fresh_root_check: bash scripts/run.sh passed in $(( $(date +%s) - t )) s"
else
  echo "fresh_root_check: bash scripts/run.sh FAILED after $(( $(date +%s) - t )) s; last lines:" >&2
  tail -30 "$logs/run.log" >&2; status=1
fi
for ((r = 1; r <= runs; r++)); do
  t=$(date +%s)
  if in_root "bash scripts/test.sh" >"$logs/test$r.log" 2>&1; then
    echo "fresh_root_check: bash scripts/test.sh (run $r of $runs) passed in $(( $(date +%s) - t )) s"
  else
    echo "fresh_root_check: bash scripts/test.sh (run $r of $runs) FAILED after $(( $(date +%s) - t )) s; last lines:" >&2
    tail -40 "$logs/test$r.log" >&2; status=1
  fi
done
exit $status
