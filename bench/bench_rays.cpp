// bench_rays: the bake's ray tracer (OccluderBvh, codec/bake/occluders.h: Embree 3 finds the
// candidates, double-precision tests decide) against zhc's own double-precision BVH (its reference
// twin, tests/reference_bvh.h) and against Embree alone (float, default scene flags, no filter: the
// lower bound of what Embree costs) on its SSE4.2 kernels, as the bake runs it, and on the best
// kernels this CPU has, on the same rays (docs/scene.md "The ray tracer").
//
// Scenes: a closed room (a box of 12 triangles) holding a grid of UV-sphere meshes, about 20k and
// 600k triangles. Rays, the same for every tracer:
//  * shadow: coherent any-hit rays from a grid of points on the floor to a point light;
//  * bounce: incoherent nearest-hit rays from random points in the room in random directions
//    (what the reflected-light pass casts).
// Each is timed on 1 and 2 threads (the rays split in contiguous halves), median of N runs, in CPU
// time (the slowest thread's, so other work on a shared machine does not count). The agreement
// column compares the bake's tracer with the reference twin: the fraction of rays where both say
// the same (hit or not; for nearest hits, the same distance within 1e-5 relative). Build times are
// wall clock (Embree's build runs on one thread: the bake's device is "threads=1").
//
//   bench_rays [--small-only] [--repeats N]
#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <time.h>

#include "bench/timing.h"
#include "codec/bake/occluders.h"
#include "tests/reference_bvh.h"

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

double thread_cpu_s() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// Runs fn(lo, hi) over [0, n) on `threads` threads (contiguous parts); returns the largest CPU time
// any thread spent.
template <class Fn>
double split(size_t n, int threads, Fn&& fn) {
    std::vector<double> cpu(static_cast<size_t>(threads));
    auto part = [&](int t) {
        const double a = thread_cpu_s();
        fn(n * t / threads, n * (t + 1) / threads);
        cpu[static_cast<size_t>(t)] = thread_cpu_s() - a;
    };
    if (threads == 1) {
        part(0);
    } else {
        std::vector<std::thread> pool;
        for (int t = 0; t < threads; ++t) pool.emplace_back(part, t);
        for (auto& th : pool) th.join();
    }
    return *std::max_element(cpu.begin(), cpu.end());
}

template <class Fn>
double median_cpu(int repeats, Fn&& run) {
    std::vector<double> t;
    for (int i = 0; i < repeats; ++i) t.push_back(run());
    std::sort(t.begin(), t.end());
    return t[t.size() / 2];
}

struct Result {
    std::vector<std::uint8_t> hit;
    std::vector<double> t;
};

// Embree alone: the triangles as one float mesh, default scene flags, no filter (what a float-only
// tracer would cost).
struct PlainEmbree {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    PlainEmbree(const std::vector<Occluder>& tris, const char* config) {
        device = rtcNewDevice(config);
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
        rtcCommitScene(scene);
    }
    PlainEmbree(const PlainEmbree&) = delete;
    PlainEmbree& operator=(const PlainEmbree&) = delete;
    ~PlainEmbree() {
        rtcReleaseScene(scene);
        rtcReleaseDevice(device);
    }
    double trace(const std::vector<Ray>& rays, bool nearest, int threads, Result& out) const {
        return split(rays.size(), threads, [&](size_t lo, size_t hi) {
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

template <class Bvh>
double trace(const Bvh& bvh, const std::vector<Ray>& rays, bool nearest, int threads, Result& out) {
    return split(rays.size(), threads, [&](size_t lo, size_t hi) {
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
    bool small_only = false;
    int repeats = 5;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--small-only")) small_only = true;
        else if (!std::strcmp(argv[i], "--repeats") && i + 1 < argc) repeats = std::max(1, std::atoi(argv[++i]));
        else {
            std::fprintf(stderr, "usage: bench_rays [--small-only] [--repeats N]\n");
            return 2;
        }
    }
    struct Size {
        const char* name;
        int spheres, lat, lon;
    };
    std::vector<Size> sizes = {{"20k", 6, 20, 15}};
    if (!small_only) sizes.push_back({"600k", 16, 34, 36});
    const int n_rays = 1 << 18;
    const auto shadow = shadow_rays(n_rays), bounce = bounce_rays(n_rays);
    std::printf("rays per second in millions (CPU time, median of %d); ratio: bake / reference; agreement: the bake's tracer against the\n"
                "reference twin; Embree SSE4.2 / best: Embree alone on its SSE4.2 kernels (as the bake) and on this CPU's best\n",
                repeats);
    std::printf("%-6s %-8s %-7s %10s %14s %12s %12s %8s %10s\n", "scene", "rays", "threads", "reference", "bake (Embree)", "Embree SSE4.2",
                "Embree best", "ratio", "agreement");
    for (const Size& sz : sizes) {
        const auto tris = room_scene(sz.spheres, sz.lat, sz.lon);
        const Timing build_ref = time_repeats(3, [&] { ReferenceBvh b(tris); });
        const Timing build_bake = time_repeats(3, [&] { OccluderBvh b(tris); });
        const ReferenceBvh ref(tris);
        const OccluderBvh bake(tris);
        const PlainEmbree plain(tris, "max_isa=sse4.2,threads=1"), native(tris, "threads=1");
        std::printf("%s: %zu triangles; build (wall, median of 3): reference %.3f s, bake %.3f s; memory: reference %.1f, bake %.1f bytes per triangle\n",
                    sz.name, tris.size(), build_ref.median_s, build_bake.median_s, double(ref.memory_bytes()) / tris.size(),
                    double(bake.memory_bytes()) / tris.size());
        for (int kind = 0; kind < 2; ++kind) {
            const auto& rays = kind == 0 ? shadow : bounce;
            const bool nearest = kind == 1;
            for (int threads : {1, 2}) {
                Result rr{std::vector<std::uint8_t>(rays.size()), std::vector<double>(rays.size())};
                Result rb = rr, rp = rr;
                const double t_ref = median_cpu(repeats, [&] { return trace(ref, rays, nearest, threads, rr); });
                const double t_bake = median_cpu(repeats, [&] { return trace(bake, rays, nearest, threads, rb); });
                const double t_plain = median_cpu(repeats, [&] { return plain.trace(rays, nearest, threads, rp); });
                const double t_native = median_cpu(repeats, [&] { return native.trace(rays, nearest, threads, rp); });
                size_t same = 0;
                for (size_t i = 0; i < rays.size(); ++i)
                    same += rr.hit[i] == rb.hit[i] && (!nearest || !rr.hit[i] || std::fabs(rr.t[i] - rb.t[i]) <= 1e-5 * std::max(1.0, rr.t[i]));
                const double n = double(rays.size()) * 1e-6;
                std::printf("%-6s %-8s %-7d %10.2f %14.2f %12.2f %12.2f %8.2f %9.4f%%\n", sz.name, nearest ? "bounce" : "shadow", threads,
                            n / t_ref, n / t_bake, n / t_plain, n / t_native, t_ref / t_bake, 100.0 * double(same) / double(rays.size()));
            }
        }
    }
    return 0;
}
