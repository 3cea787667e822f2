// zhc/codec/sh/cubemap.h — cube-face environment maps: six square faces of N x N pixels stored one
// below the other (an image N wide and 6N high), faces in the order +X -X +Y -Y +Z -Z of the
// source's frame (Y up). Two layouts are described by a table (CubeLayout): OpenEXR's
// (Imf::CubeMap, ImfEnvmap.h) and the graphics APIs' (Vulkan's "Cube Map Face Selection" table,
// which is Direct3D's too; KTX2 and DDS cube maps store their faces in it).
//
// A face maps face coordinates (u, v) in [-1, 1]^2 (u along a row, left to right; v down the
// rows, row 0 at the face's top) to the direction  major + u * u_axis + v * v_axis  (source frame,
// normalised). Pixel (col, row) has face coordinates
//   centre to centre (OpenEXR): u = 2 col / (N-1) - 1, v = 2 row / (N-1) - 1 — the first and last
//     pixel centres lie ON the cube's edges; its footprint is [u - 1/(N-1), u + 1/(N-1)] x [...]
//     clipped to the face (edge pixels cover half a pixel, corner pixels a quarter);
//   texel centres (Vulkan/D3D): u = (2 col + 1) / N - 1, v = (2 row + 1) / N - 1 (s = (col + 0.5)/N,
//     u = 2 s - 1); its footprint is the texel's square [2 col / N - 1, 2 (col + 1) / N - 1] x [...].
// Either way the six faces tile the sphere exactly once.
//
// OpenEXR (checked against Imf::CubeMap in tests/test_real_world.cpp):
//   +X: ( 1, -v,  u)   -X: (-1, -v, -u)   +Y: ( u,  1, -v)
//   -Y: ( u, -1,  v)   +Z: (-u, -v,  1)   -Z: ( u, -v, -1)
// Vulkan / D3D (sc = u, tc = v of the spec's table; a left-handed cube: the OpenEXR cube mirrored
// in z):
//   +X: ( 1, -v, -u)   -X: (-1, -v,  u)   +Y: ( u,  1,  v)
//   -Y: ( u, -1, -v)   +Z: ( u, -v,  1)   -Z: (-u, -v, -1)
// Both source frames are Y-up and map to zhc's Z-up frame as (x, y, z)_zhc = (z, x, y)_source
// (docs/conventions.md for OpenEXR; the glTF mapping of docs/gltf-extension.md for the APIs:
// API +Y is zhc +Z). A D3D cube map is read with the same texel layout (D3D's face table is the
// same as Vulkan's).
//
// Exact solid angle of a footprint [u0, u1] x [v0, v1]: the projected-rectangle formula
//   Omega = F(u1, v1) - F(u0, v1) - F(u1, v0) + F(u0, v0),  F(a, b) = atan2(a b, sqrt(1 + a^2 + b^2))
// (sum over the sphere: 4 pi). N = 1: each face is one pixel covering the whole face.
//
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
#pragma once

#include <cstddef>

#include "codec/sh/sh.h"

namespace zhc {

struct CubeFaceAxes {
    signed char major[3], u_axis[3], v_axis[3];  // source frame (x, y, z), entries -1, 0, 1
};
struct CubeLayout {
    CubeFaceAxes face[6];   // +X -X +Y -Y +Z -Z
    bool centre_to_centre;  // true: OpenEXR's pixel positions; false: texel centres (Vulkan/D3D)
};
extern const CubeLayout kCubeLayoutOpenExr;
extern const CubeLayout kCubeLayoutVulkan;  // also D3D's, KTX2's and DDS's

// Direction (zhc frame, unit) of the centre of pixel (col, row) of face `face` (0..5) in a cube
// map of face size n. col, row may be fractional.
Vec3 cube_direction(const CubeLayout& layout, int face, double col, double row, int n);
// Exact solid angle of pixel (col, row)'s footprint (the same on every face).
double cube_pixel_solid_angle(const CubeLayout& layout, int col, int row, int n);
// The pixel whose centre is nearest to zhc direction d (the face d's dominant axis selects).
void cube_nearest_pixel(const CubeLayout& layout, Vec3 d, int n, int* face, int* col, int* row);

// SH3 projection of a cube map (interleaved RGB floats, n wide, 6n high, `row_stride` floats per
// row): every pixel's value times the exact solid angle of its footprint times the basis at the
// footprint's centre direction, accumulated in double in a fixed order (the result does not
// depend on `threads`). Constant maps give exactly one non-zero band up to rounding (the cube's
// symmetry cancels bands 1 and 2); smooth maps converge as O(1/n^2).
Sh3Radiance project_cube(const CubeLayout& layout, const float* rgb, int n, size_t row_stride, int threads = 1);

// OpenEXR's layout (the functions above with kCubeLayoutOpenExr).
Vec3 cube_openexr_direction(int face, double col, double row, int n);
double cube_openexr_pixel_solid_angle(int col, int row, int n);
Sh3Radiance project_cube_openexr(const float* rgb, int n, size_t row_stride, int threads = 1);

}  // namespace zhc
