// zhc/codec/isa.h — internal to codec/: the AVX2 twins of hot loops (BC6H encoder, BC4/BC5 index
// search, the IrradZ fit's vector lanes). A twin is the same source compiled a second time for
// AVX2, between ZHC_AVX2_BEGIN and ZHC_AVX2_END, and chosen at run time by cpu_has_avx2(); both
// builds compute the same floats (zhc_codec is built with -ffp-contract=off and the AVX2 target
// does not enable FMA), which each user's tests check bit for bit. x86-64 GCC and clang only;
// elsewhere ZHC_AVX2_TWIN is 0 and only the baseline build exists.
#pragma once

#if (defined(__x86_64__) || defined(__i386__)) && (defined(__GNUC__) || defined(__clang__))
#define ZHC_AVX2_TWIN 1
#if defined(__clang__)
#define ZHC_AVX2_BEGIN _Pragma("clang attribute push(__attribute__((target(\"avx2\"))), apply_to = function)")
#define ZHC_AVX2_END _Pragma("clang attribute pop")
#else
#define ZHC_AVX2_BEGIN _Pragma("GCC push_options") _Pragma("GCC target(\"avx2\")")
#define ZHC_AVX2_END _Pragma("GCC pop_options")
#endif
#else
#define ZHC_AVX2_TWIN 0
#define ZHC_AVX2_BEGIN
#define ZHC_AVX2_END
#endif

namespace zhc {

// Whether this CPU runs AVX2 code (false where there is no AVX2 twin).
inline bool cpu_has_avx2() {
#if ZHC_AVX2_TWIN
    static const bool has = __builtin_cpu_supports("avx2");
    return has;
#else
    return false;
#endif
}

}  // namespace zhc
