// bench_rays: zhc's BVH (codec/bake/occluders.h) against Embree 3 (Debian libembree-dev, where the
// build finds it) on the same rays, to choose the bake's ray tracer by measurement
// (docs/scene.md "The ray tracer").
//
// Scenes: a closed room (a box of 12 triangles) holding a grid of UV-sphere meshes, about 20k and
// 600k triangles. Rays, the same for both tracers:
//  * shadow: coherent any-hit rays from a grid of points on the floor to a point light;
//  * bounce: incoherent nearest-hit rays from random points in the room in random directions
//    (what the reflected-light pass casts).
// Each is timed on 1 and 2 threads (the rays split in contiguous halves), median of 5 runs; the
// agreement column is the fraction of rays where both say the same (hit or not; for nearest hits,
// the same distance within 1e-4 relative). Embree traces in single precision, zhc in double.
//
//   bench_rays [--small-only] [--repeats N]
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "bench/timing.h"
#include "codec/bake/occluders.h"

#ifdef ZHC_EMBREE
#include <embree3/rtcore.h>
#endif

namespace {

using namespace zhc;
using namespace zhc::bench;

struct Ray {
    Vec3 o, d;
    double t_max;
};

std::vector<Occluder> room_scene(int spheres_per_axis, int lat, int lon) {
    std::vector<Occluder> tris;
    const Vec3 lo{-10, -10, 0}, hi{10, 10, 6};
    auto v = [&](int i) { return Vec3{(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z}; };
    const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& q : quads) {
        tris.push_back(triangle_occluder(v(q[0]), v(q[1]), v(q[2])));
        tris.push_back(triangle_occluder(v(q[0]), v(q[2]), v(q[3])));
    }
    const double step = 20.0 / spheres_per_axis;
    for (int i = 0; i < spheres_per_axis; ++i)
        for (int j = 0; j < spheres_per_axis; ++j) {
            const Vec3 c{-10 + (i + 0.5) * step, -10 + (j + 0.5) * step, 2.0 + 0.5 * ((i + j) % 3)};
            const auto s = uv_sphere_triangles(c, 0.3 * step, lat, lon);
            tris.insert(tris.end(), s.begin(), s.end());
        }
    return tris;
}

std::vector<Ray> shadow_rays(int n) {
    std::vector<Ray> rays;
    const Vec3 light{0.3, -0.2, 5.5};
    const int side = static_cast<int>(std::sqrt(double(n)));
    for (int i = 0; i < side; ++i)
        for (int j = 0; j < side; ++j) {
            const Vec3 o{-9.9 + 19.8 * (i + 0.5) / side, -9.9 + 19.8 * (j + 0.5) / side, 0.01};
            const Vec3 v = light - o;
            const double d = length(v);
            rays.push_back({o, (1.0 / d) * v, d});
        }
    return rays;
}

std::vector<Ray> bounce_rays(int n) {
    std::mt19937_64 rng(12345);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Ray> rays;
    for (int k = 0; k < n; ++k) {
        const Vec3 o{-9.9 + 19.8 * u(rng), -9.9 + 19.8 * u(rng), 0.05 + 5.9 * u(rng)};
        const double z = 1 - 2 * u(rng), phi = 2 * kPi * u(rng), r = std::sqrt(std::max(0.0, 1 - z * z));
        rays.push_back({o, {r * std::cos(phi), r * std::sin(phi), z}, std::numeric_limits<double>::infinity()});
    }
    return rays;
}

template <class Fn>
void split(size_t n, int threads, Fn&& fn) {
    if (threads == 1) {
        fn(0, n);
        return;
    }
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) pool.emplace_back([&, t] { fn(n * t / threads, n * (t + 1) / threads); });
    for (auto& th : pool) th.join();
}

struct Result {
    std::vector<std::uint8_t> hit;
    std::vector<double> t;
};

#ifdef ZHC_EMBREE
struct Embree {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    explicit Embree(const std::vector<Occluder>& tris) {
        device = rtcNewDevice(nullptr);
        scene = rtcNewScene(device);
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        float* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * tris.size()));
        unsigned* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), tris.size()));
        for (size_t i = 0; i < tris.size(); ++i) {
            const Vec3 v[3] = {tris[i].v0, tris[i].v1, tris[i].v2};
            for (int k = 0; k < 3; ++k) {
                vb[9 * i + 3 * k] = float(v[k].x);
                vb[9 * i + 3 * k + 1] = float(v[k].y);
                vb[9 * i + 3 * k + 2] = float(v[k].z);
                ib[3 * i + k] = unsigned(3 * i + k);
            }
        }
        rtcCommitGeometry(g);
        rtcAttachGeometry(scene, g);
        rtcReleaseGeometry(g);
        rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
        rtcCommitScene(scene);
    }
    ~Embree() {
        rtcReleaseScene(scene);
        rtcReleaseDevice(device);
    }
    void trace(const std::vector<Ray>& rays, bool nearest, int threads, Result& out) const {
        split(rays.size(), threads, [&](size_t lo, size_t hi) {
            RTCIntersectContext ctx;
            rtcInitIntersectContext(&ctx);
            for (size_t i = lo; i < hi; ++i) {
                const Ray& r = rays[i];
                RTCRayHit rh;
                rh.ray.org_x = float(r.o.x);
                rh.ray.org_y = float(r.o.y);
                rh.ray.org_z = float(r.o.z);
                rh.ray.dir_x = float(r.d.x);
                rh.ray.dir_y = float(r.d.y);
                rh.ray.dir_z = float(r.d.z);
                rh.ray.tnear = 1e-6f;
                rh.ray.tfar = std::isinf(r.t_max) ? std::numeric_limits<float>::infinity() : float(r.t_max);
                rh.ray.mask = 0xFFFFFFFFu;
                rh.ray.flags = 0;
                rh.ray.time = 0;
                if (nearest) {
                    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                    rtcIntersect1(scene, &ctx, &rh);
                    out.hit[i] = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
                    out.t[i] = out.hit[i] ? rh.ray.tfar : 0.0;
                } else {
                    rtcOccluded1(scene, &ctx, &rh.ray);
                    out.hit[i] = rh.ray.tfar < 0;
                }
            }
        });
    }
};
#endif

void zhc_trace(const OccluderBvh& bvh, const std::vector<Ray>& rays, bool nearest, int threads, Result& out) {
    split(rays.size(), threads, [&](size_t lo, size_t hi) {
        for (size_t i = lo; i < hi; ++i) {
            const Ray& r = rays[i];
            if (nearest) {
                const RayHit h = bvh.nearest(r.o, r.d, 1e-6, r.t_max);
                out.hit[i] = h.hit;
                out.t[i] = h.hit ? h.t : 0.0;
            } else {
                out.hit[i] = bvh.occluded(r.o, r.d, 1e-6, r.t_max);
            }
        }
    });
}

}  // namespace

int main(int argc, char** argv) {
    using namespace zhc::bench;
    bool small_only = false;
    int repeats = 5;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--small-only")) small_only = true;
        else if (!std::strcmp(argv[i], "--repeats") && i + 1 < argc) repeats = std::atoi(argv[++i]);
        else {
            std::fprintf(stderr, "usage: bench_rays [--small-only] [--repeats N]\n");
            return 2;
        }
    }
#ifndef ZHC_EMBREE
    std::printf("bench_rays: built without Embree (libembree-dev not found): zhc's BVH only\n");
#endif
    struct Size {
        const char* name;
        int spheres, lat, lon;
    };
    std::vector<Size> sizes = {{"20k", 6, 20, 15}};
    if (!small_only) sizes.push_back({"600k", 16, 34, 36});
    const int n_rays = 1 << 18;
    const auto shadow = shadow_rays(n_rays), bounce = bounce_rays(n_rays);
    std::printf("%-6s %-8s %-7s %12s %12s %8s %10s\n", "scene", "rays", "threads", "zhc Mray/s", "Embree Mray/s", "ratio", "agreement");
    for (const Size& sz : sizes) {
        const auto tris = room_scene(sz.spheres, sz.lat, sz.lon);
        Timing build_zhc = time_repeats(1, [&] { OccluderBvh b(tris); });
        const OccluderBvh bvh(tris);
#ifdef ZHC_EMBREE
        Timing build_embree = time_repeats(1, [&] { Embree e(tris); });
        const Embree embree(tris);
        std::printf("%s: %zu triangles; build zhc %.3f s, Embree %.3f s\n", sz.name, tris.size(), build_zhc.median_s, build_embree.median_s);
#else
        std::printf("%s: %zu triangles; build zhc %.3f s\n", sz.name, tris.size(), build_zhc.median_s);
#endif
        for (int kind = 0; kind < 2; ++kind) {
            const auto& rays = kind == 0 ? shadow : bounce;
            const bool nearest = kind == 1;
            for (int threads : {1, 2}) {
                Result rz{std::vector<std::uint8_t>(rays.size()), std::vector<double>(rays.size())};
                const Timing tz = time_repeats(repeats, [&] { zhc_trace(bvh, rays, nearest, threads, rz); });
                double embree_rate = 0, agree = 1;
#ifdef ZHC_EMBREE
                Result re{std::vector<std::uint8_t>(rays.size()), std::vector<double>(rays.size())};
                const Timing te = time_repeats(repeats, [&] { embree.trace(rays, nearest, threads, re); });
                embree_rate = rays.size() / te.median_s * 1e-6;
                size_t same = 0;
                for (size_t i = 0; i < rays.size(); ++i)
                    same += rz.hit[i] == re.hit[i] && (!nearest || !rz.hit[i] || std::fabs(rz.t[i] - re.t[i]) <= 1e-4 * std::max(1.0, rz.t[i]));
                agree = double(same) / rays.size();
#endif
                const double zhc_rate = rays.size() / tz.median_s * 1e-6;
                std::printf("%-6s %-8s %-7d %12.2f %12.2f %8.2f %9.4f%%\n", sz.name, nearest ? "bounce" : "shadow", threads, zhc_rate, embree_rate,
                            embree_rate > 0 ? embree_rate / zhc_rate : 0.0, 100 * agree);
            }
        }
    }
    return 0;
}
