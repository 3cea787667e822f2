// ZH3 representations — to be filled by the ZH3 work (issue 3).
#include "codec.h"
namespace zhc {
std::span<const Codec> zh3_codecs() { return {}; }
}  // namespace zhc
