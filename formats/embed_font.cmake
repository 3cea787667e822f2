# cmake -DIN=font.ttf -DOUT=embedded_font.cpp -P embed_font.cmake: writes the font's bytes as a C++
# array (zhc::kEmbeddedFont, zhc::kEmbeddedFontSize) for formats/report/raster.cpp. Run at build time by
# formats/pictures.cmake; the font itself is never committed.
file(READ "${IN}" hex HEX)
string(LENGTH "${hex}" n)
math(EXPR bytes "${n} / 2")
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," body "${hex}")
string(REGEX REPLACE "(0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,)" "\\1\n" body "${body}")
get_filename_component(name "${IN}" NAME)
file(WRITE "${OUT}.tmp"
  "// Generated at build time by formats/embed_font.cmake from ${name} (Debian fonts-dejavu-core). Do not edit.\n"
  "#include <cstddef>\n\nnamespace zhc {\n"
  "extern const unsigned char kEmbeddedFont[];\nextern const std::size_t kEmbeddedFontSize;\n"
  "alignas(4) const unsigned char kEmbeddedFont[] = {\n${body}\n};\n"
  "const std::size_t kEmbeddedFontSize = ${bytes};\n}  // namespace zhc\n")
file(RENAME "${OUT}.tmp" "${OUT}")
