// zhc/codec/cubemap.h — cube-face environment maps in OpenEXR's layout (Imf::CubeMap,
// ImfEnvmap.h): one image N pixels wide and 6N high, faces stacked top to bottom in the order
// +X -X +Y -Y +Z -Z of OpenEXR's frame (Y up).
//
// Pixel -> direction (OpenEXR's own mapping, checked against Imf::CubeMap in
// tests/test_real_world.cpp): within a face, pixel (col, row) (row 0 at the face's top) has face
// coordinates u = 2 col / (N-1) - 1, v = 2 row / (N-1) - 1 — "centre to centre": the first and
// last pixel centres lie ON the cube's edges — and looks along (OpenEXR frame)
//   +X: ( 1, -v,  u)   -X: (-1, -v, -u)   +Y: ( u,  1, -v)
//   -Y: ( u, -1,  v)   +Z: (-u, -v,  1)   -Z: ( u, -v, -1)
// (normalised). zhc's frame is (x, y, z)_zhc = (z, x, y)_OpenEXR (docs/conventions.md).
//
// Footprints: pixel (col, row) stands for the face rectangle [u - 1/(N-1), u + 1/(N-1)] x [v -
// 1/(N-1), v + 1/(N-1)] clipped to the face [-1, 1]^2 (edge pixels cover half a pixel, corner
// pixels a quarter), so the six faces tile the sphere exactly once. Its exact solid angle is the
// projected-rectangle formula  Omega = F(u1, v1) - F(u0, v1) - F(u1, v0) + F(u0, v0),
// F(a, b) = atan2(a b, sqrt(1 + a^2 + b^2))  (sum over the sphere: 4 pi). N = 1: each face is
// one pixel covering the whole face.
#pragma once

#include <cstddef>

#include "sh.h"

namespace zhc {

// Direction (zhc frame, unit) of the centre of pixel (col, row) of face `face` (0..5 = +X -X +Y
// -Y +Z -Z of OpenEXR) in a cube map of face size n. col, row may be fractional.
Vec3 cube_openexr_direction(int face, double col, double row, int n);
// Exact solid angle of pixel (col, row)'s clipped footprint (the same on every face).
double cube_openexr_pixel_solid_angle(int col, int row, int n);

// SH3 projection of an OpenEXR cube map (interleaved RGB floats, n wide, 6n high, `row_stride`
// floats per row): every pixel's value times the exact solid angle of its footprint times the
// basis at the footprint's centre direction, accumulated in double in a fixed order (the result
// does not depend on `threads`). Constant maps give exactly one non-zero band up to rounding (the
// cube's symmetry cancels bands 1 and 2); smooth maps converge as O(1/n^2).
Sh3Radiance project_cube_openexr(const float* rgb, int n, size_t row_stride, int threads = 1);

}  // namespace zhc
