# cmake -DVALIDATOR=... -DVERSION="310 es"|450 -DSTAGE=comp|frag -DLIBRARY=zhc.glsl -DOUT_DIR=... -P
# Wraps runtime/zhc.glsl in a #version line and a main that calls every public entry point, then
# compiles it with glslangValidator (fails the test on any error or warning-as-error).
file(READ "${LIBRARY}" library)
if(STAGE STREQUAL "comp")
  # The compute stage also binds the probe words for the volume functions (ZHC_VOLUME_WORD).
  set(prelude "
layout(std430, binding = 0) readonly buffer Words { uint words[]; };
#define ZHC_VOLUME_WORD(i) words[i]
")
  set(main "
layout(local_size_x = 64) in;
layout(std430, binding = 1) writeonly buffer Out { vec4 outv[]; };
uniform ZhcFormat uFormat;
uniform ZhcVolume uVolume;
void main() {
    uint i = gl_GlobalInvocationID.x;
    uint w[27];
    for (uint k = 0u; k < 27u; ++k) w[k] = words[i * 27u + k];
    ZhcSh3 s = zhcDecode(w, uFormat);
    vec3 n = normalize(vec3(1.0, 2.0, 3.0));
    vec3 e = zhcIrradiance(w, uFormat, n) + zhcIrradianceSh3(s, n) + zhcEvalSh3(s, n);
    e += zhcIrradZIrradiance(vec3(1.0), 0.5, vec2(0.5), n, ZHC_IRRADZ_HHD);
    e += zhcHlshIrradiance(s.c[0], s.c[1], s.c[2], s.c[3], n);
    e += zhcUnpackR11G11B10F(w[0]) + zhcUnpackRGB9E5(w[1]) + vec3(zhcUnpackHalf(w[2]));
    e += zhcVolumeIrradiance(uVolume, uFormat, vec3(float(i), 0.5, 2.0), n) + zhcVolumeSh3(uVolume, uFormat, n).c[4];
    e += zhcVolumeTetraIrradiance(uvec4(i, 1u, 2u, 3u), vec4(0.5, 0.25, 0.25, 0.0), uFormat, n) +
         zhcVolumeTetraSh3(uvec4(0u, i, 2u, 3u), vec4(0.25), uFormat).c[4];
    outv[i] = vec4(e, 1.0);
}
")
else()
  set(prelude "")
  set(main "
uniform ZhcFormat uFormat;
uniform highp uvec4 uWords;
uniform vec3 uNormal;
uniform sampler2D uIz;
uniform sampler2D uWa;
uniform sampler2D uDir;
in vec2 vUv;
in vec3 vNormal;
out vec4 outColour;
void main() {
    ZhcSh3 s = zhcDecodeZh3Q16(uWords, uFormat);
    vec3 e = zhcIrradianceZh3Q16(uWords, uFormat, uNormal) + zhcIrradianceSh2Q(uWords, uFormat, uNormal);
    e += zhcIrradianceSh3(s, uNormal);
    e += zhcIrradZIrradiance(texture(uIz, vUv).rgb, texture(uWa, vUv).r, texture(uDir, vUv).rg,
                             normalize(vNormal), ZHC_IRRADZ_AHD);
    outColour = vec4(e, 1.0);
}
")
endif()
string(REPLACE " " "" tag "${VERSION}")
file(MAKE_DIRECTORY "${OUT_DIR}")
set(out "${OUT_DIR}/zhc_${tag}.${STAGE}")
file(WRITE "${out}" "#version ${VERSION}\n${prelude}${library}${main}")
execute_process(COMMAND "${VALIDATOR}" "${out}" RESULT_VARIABLE rc OUTPUT_VARIABLE log ERROR_VARIABLE log)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "glslangValidator ${out} failed:\n${log}")
endif()
message(STATUS "glslangValidator ${out}: ok")
