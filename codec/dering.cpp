// Deringing representations — to be filled by the deringing work (issue 4).
#include "codec.h"
namespace zhc {
std::span<const Codec> dering_codecs() { return {}; }
}  // namespace zhc
