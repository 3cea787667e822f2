// Quantised layouts — to be filled by the storage work (issue 5).
#include "codec.h"
namespace zhc {
std::span<const Codec> quantized_codecs() { return {}; }
}  // namespace zhc
