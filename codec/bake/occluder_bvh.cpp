// OccluderBvh on Embree 3 (docs/scene.md "The ray tracer"): Embree finds the candidates, zhc's
// double-precision tests decide.
//
// Layout. Triangles are one Embree triangle mesh (float vertices, three per triangle, the index
// buffer one entry per occluder: a sphere's or box's entry names no vertex, which Embree skips, so a
// triangle's Embree primitive ID is its occluder index). Spheres and boxes are one Embree user
// geometry whose callbacks run ray_nearest / ray_hits on the double occluder. Embree sees the scene
// centred on its bounding box and scaled by a power of two into [-1, 1] (the scaling is exact, and
// the float vertices keep a relative 2^-24 of the scene's size wherever it lies in space); a ray
// enters that frame clipped to the box, so no float overflows whatever the coordinates.
//
// Decisions. The scene is built with RTC_SCENE_FLAG_ROBUST (conservative node tests, Embree's
// Pluecker triangle test) and each triangle's float vertices are grown by kGrow (2^-18 of the
// scene's half size) about its centroid, so neighbours overlap and no ray slips between them.
// Embree's float test decides whether a ray meets a triangle; the distance, the face (`back`) and
// the interval (t_min, t_max) are decided in double by an intersection filter (ray_triangle_plane:
// the same bits as ray_nearest's t). The ray Embree traces starts kMargin (2^-16 of the half size)
// before the interval, and its far end stays kMargin beyond the best double hit so far, so every
// candidate within float error of a decision reaches the double test. nearest() keeps the smallest
// (t, index) over the candidates: which primitive wins does not depend on the order Embree visits
// them in, except where a ray meets a triangle so obliquely (within about 1/256 radian of its
// plane) that Embree's float distance errs by more than kMargin next to another hit; the build is
// single-threaded and deterministic, so that order is the same on every run too. Spheres and boxes
// are exactly the double tests. Hits and misses differ from a double-precision tracer only for
// rays within about kGrow of a triangle's edge (tests/reference_bvh.h, test_scene_mesh).
//
// Device: "max_isa=sse4.2,threads=1". Embree picks kernels by the CPU's instruction set, and its
// AVX2 and AVX-512 kernels contract multiply-adds, so decisions within float rounding of an edge
// differ between them (measured on bench_rays' 608k-triangle room: of 262,144 rays aimed exactly at
// vertices and edge points, 327 nearest hits differ between the SSE4.2 and the AVX2 kernels, at
// the same point to 1e-13 but on the other triangle; SSE2 and SSE4.2 agree on all; random rays
// agree on every kernel). Capped at SSE4.2 (plain IEEE float), every x86-64 CPU with SSE4.2 runs
// the same kernels and a bake gives the same bytes on all of them; bench_rays measures the cost.
// threads=1: the build runs on the calling thread (the bake's own threads are its --threads) and
// gives one BVH for one input (nearest() depends on its shape only in the oblique case above).
#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>

#include "codec/bake/occluders.h"

namespace zhc {

namespace {

constexpr unsigned kNoVertex = 0xFFFFFFFFu;
// The margin around every decision, in the normalised frame (scene half size = at most 1): float's
// relative error there is 2^-24, so 2^-16 is 256 times that (rays within about 1/256 radian of a
// triangle's plane may still see a hit's distance rounded past it; their hit then goes to the
// triangle Embree reports first, deterministically).
constexpr double kMargin = 1.0 / 65536.0;
// How far each triangle's float vertices move out from its centroid, in the same frame: 2^-18.
// Neighbouring triangles then overlap along shared edges and around shared vertices, so no ray
// slips between them. Embree's watertight test closes edges but not vertices: rays aimed exactly at
// the vertices of closed sphere meshes from inside escaped 14 times in 400,000 without the growth;
// from the corners of a scene 1000 times the spheres' size, 2^-21 still let 5 of 93,410 rays through
// and 2^-20 none. 2^-18 is 4 times that.
constexpr double kGrow = 1.0 / 262144.0;

#if defined(__x86_64__) || defined(_M_X64) || defined(__i386__)
constexpr const char* kDeviceConfig = "max_isa=sse4.2,threads=1,verbose=0";
#else
constexpr const char* kDeviceConfig = "threads=1,verbose=0";
#endif

// A double rounded to the float not below it.
float float_up(double x) {
    float f = static_cast<float>(x);
    if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
    return f;
}
float float_down(double x) {
    float f = static_cast<float>(x);
    if (static_cast<double>(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
    return f;
}

}  // namespace

struct OccluderBvh::Impl {
    std::vector<Occluder> prims;        // as given; a triangle's index is its Embree primitive ID
    std::vector<std::uint32_t> solids;  // user-geometry primitive ID -> occluder index
    Vec3 lo, hi;                        // exact box of every occluder
    Vec3 center;                        // of the box; the normalised frame is (x - center) / scale
    double scale = 1, inv_scale = 1;    // powers of two
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;         // triangles and solids: rays, overlaps_box
    RTCScene solid_scene = nullptr;   // solids alone: inside_any_solid
    unsigned tri_geom = RTC_INVALID_GEOMETRY_ID;  // the triangle mesh's geometry ID in `scene`
    std::atomic<std::int64_t> embree_bytes{0};
    std::mutex error_mutex;
    std::string error;  // Embree's first error (record_error)

    Impl() = default;
    Impl(const Impl&) = delete;
    Impl& operator=(const Impl&) = delete;
    ~Impl() {
        if (solid_scene) rtcReleaseScene(solid_scene);
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
    void to_frame(Vec3 p, float out[3]) const {
        const Vec3 q = inv_scale * (p - center);
        out[0] = static_cast<float>(q.x);
        out[1] = static_cast<float>(q.y);
        out[2] = static_cast<float>(q.z);
    }
    std::uint32_t index_of(unsigned geom, unsigned prim) const { return geom == tri_geom ? prim : solids[prim]; }
};

namespace {

using Impl = OccluderBvh::Impl;

// One query's state; Embree hands `ctx` back to the callbacks (it is the first member).
struct Query {
    RTCIntersectContext ctx;
    const Impl* impl;
    Vec3 o, d;
    double t_min, t_max;
    double start;  // Embree's ray starts at o + start d; its t' = (t - start) / scale
    bool nearest;
    RayHit best;
    // Embree's far end for a double distance t: kMargin past it, rounded up.
    float far_of(double t) const { return float_up((t - start) * impl->inv_scale + kMargin); }
};

// Sets up Embree's ray for the double ray (o, d, t_min, t_max): false when no part of the ray that
// matters meets the scene's box (then nothing can be hit). The part that matters runs from the
// origin (a ray starting inside a solid is blocked) or t_min, whichever is first, to t_max.
bool setup(const Impl& im, Vec3 o, Vec3 d, double t_min, double t_max, Query& q, RTCRay& ray) {
    const double pad = kMargin * im.scale;
    double t0 = std::min(t_min, 0.0), t1 = t_max;
    for (int a = 0; a < 3; ++a) {
        const double lo = im.lo[a] - pad, hi = im.hi[a] + pad, oa = o[a], da = d[a];
        if (da == 0.0) {
            if (oa < lo || oa > hi) return false;
            continue;
        }
        double ta = (lo - oa) / da, tb = (hi - oa) / da;
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
        if (!(t0 <= t1)) return false;
    }
    rtcInitIntersectContext(&q.ctx);
    q.impl = &im;
    q.o = o;
    q.d = d;
    q.t_min = t_min;
    q.t_max = t_max;
    q.start = t0 - pad;
    q.best = RayHit{};
    float org[3];
    im.to_frame(o + q.start * d, org);
    ray.org_x = org[0];
    ray.org_y = org[1];
    ray.org_z = org[2];
    ray.dir_x = static_cast<float>(d.x);
    ray.dir_y = static_cast<float>(d.y);
    ray.dir_z = static_cast<float>(d.z);
    ray.tnear = 0.0f;
    ray.tfar = q.far_of(t1);
    ray.time = 0.0f;
    ray.mask = 0xFFFFFFFFu;
    ray.id = 0;
    ray.flags = 0;
    return true;
}

// A candidate at double distance t: is it the best so far (smaller t, or the same t and a lower
// index)? Records it when it is.
bool offer(Query& q, double t, bool back, std::uint32_t index) {
    if (q.best.hit && (t > q.best.t || (t == q.best.t && index >= q.best.prim))) return false;
    q.best = {true, back, t, index};
    return true;
}

// Triangles: Embree's float test found the ray inside the triangle; the double test decides the rest.
void triangle_filter(const RTCFilterFunctionNArguments* args) {
    Query& q = *reinterpret_cast<Query*>(args->context);
    const unsigned prim = RTCHitN_primID(args->hit, args->N, 0);
    double t = 0;
    bool back = false;
    if (!ray_triangle_plane(q.impl->prims[prim], q.o, q.d, &t, &back) || !(t > q.t_min && t < q.t_max)) {
        args->valid[0] = 0;
        return;
    }
    if (!q.nearest) return;  // any hit: accepted, Embree stops
    if (!offer(q, t, back, prim)) {
        args->valid[0] = 0;
        return;
    }
    RTCRayN_tfar(args->ray, args->N, 0) = q.far_of(t);
}

void solid_bounds(const RTCBoundsFunctionArguments* args) {
    const Impl& im = *static_cast<const Impl*>(args->geometryUserPtr);
    Vec3 lo, hi;
    occluder_bounds(im.prims[im.solids[args->primID]], &lo, &hi);
    const Vec3 a = im.inv_scale * (lo - im.center), b = im.inv_scale * (hi - im.center);
    RTCBounds* out = args->bounds_o;
    out->lower_x = float_down(a.x);
    out->lower_y = float_down(a.y);
    out->lower_z = float_down(a.z);
    out->upper_x = float_up(b.x);
    out->upper_y = float_up(b.y);
    out->upper_z = float_up(b.z);
}

void solid_intersect(const RTCIntersectFunctionNArguments* args) {
    if (!args->valid[0]) return;
    Query& q = *reinterpret_cast<Query*>(args->context);
    const std::uint32_t index = q.impl->solids[args->primID];
    const RayHit h = ray_nearest(q.impl->prims[index], q.o, q.d, q.t_min, q.t_max);
    if (!h.hit || !offer(q, h.t, h.back, index)) return;
    RTCRayHitN* rh = args->rayhit;
    RTCRayN_tfar(RTCRayHitN_RayN(rh, args->N), args->N, 0) = q.far_of(h.t);
    RTCHitN* hit = RTCRayHitN_HitN(rh, args->N);
    RTCHitN_geomID(hit, args->N, 0) = args->geomID;
    RTCHitN_primID(hit, args->N, 0) = args->primID;
}

void solid_occluded(const RTCOccludedFunctionNArguments* args) {
    if (!args->valid[0]) return;
    const Query& q = *reinterpret_cast<const Query*>(args->context);
    if (ray_hits(q.impl->prims[q.impl->solids[args->primID]], q.o, q.d, q.t_min, q.t_max))
        RTCRayN_tfar(args->ray, args->N, 0) = -std::numeric_limits<float>::infinity();
}

// Point queries: inside_any_solid (a point) and overlaps_box (a box), decided in double.
struct PointQuery {
    const Impl* impl;
    Vec3 p, lo, hi;
    bool box;  // overlaps_box over the whole scene; else inside_any_solid over the solids' scene
    bool found = false;
};

bool point_callback(RTCPointQueryFunctionArguments* args) {
    PointQuery& pq = *static_cast<PointQuery*>(args->userPtr);
    if (pq.found) return false;
    const Impl& im = *pq.impl;
    const Occluder& occ = im.prims[pq.box ? im.index_of(args->geomID, args->primID) : im.solids[args->primID]];
    if (pq.box) {
        Vec3 lo, hi;
        occluder_bounds(occ, &lo, &hi);
        pq.found = !(hi.x < pq.lo.x || lo.x > pq.hi.x || hi.y < pq.lo.y || lo.y > pq.hi.y || hi.z < pq.lo.z || lo.z > pq.hi.z);
    } else {
        pq.found = inside_solid(occ, pq.p);
    }
    if (!pq.found) return false;
    args->query->radius = 0.0f;  // found: cull what remains
    return true;
}

void record_error(void* user, RTCError code, const char* what) {
    Impl& im = *static_cast<Impl*>(user);
    const std::lock_guard<std::mutex> lock(im.error_mutex);
    if (im.error.empty()) im.error = code == RTC_ERROR_OUT_OF_MEMORY ? "out of memory" : std::string(what ? what : "unknown error");
}

bool count_bytes(void* user, ssize_t bytes, bool post) {
    static_cast<Impl*>(user)->embree_bytes.fetch_add(bytes, std::memory_order_relaxed);
    return true;
}

void check(const Impl& im) {
    if (im.error.empty()) return;
    if (im.error == "out of memory") throw std::bad_alloc();
    throw std::runtime_error("Embree: " + im.error);
}

}  // namespace

OccluderBvh::OccluderBvh(const std::vector<Occluder>& occluders) { build(std::vector<Occluder>(occluders)); }

OccluderBvh::OccluderBvh(std::vector<Occluder>&& occluders) {
    std::vector<Occluder> mine(std::move(occluders));
    occluders.clear();
    occluders.shrink_to_fit();
    build(std::move(mine));
}

void OccluderBvh::build(std::vector<Occluder>&& occluders) {
    if (occluders.empty()) return;
    auto im = std::make_shared<Impl>();
    im->prims = std::move(occluders);
    im->prims.shrink_to_fit();
    const std::vector<Occluder>& prims = im->prims;
    std::size_t triangles = 0;
    const double inf = std::numeric_limits<double>::infinity();
    Vec3 lo{inf, inf, inf}, hi{-inf, -inf, -inf};
    for (std::size_t i = 0; i < prims.size(); ++i) {
        Vec3 a, b;
        occluder_bounds(prims[i], &a, &b);
        lo = {std::min(lo.x, a.x), std::min(lo.y, a.y), std::min(lo.z, a.z)};
        hi = {std::max(hi.x, b.x), std::max(hi.y, b.y), std::max(hi.z, b.z)};
        if (prims[i].kind == OccluderKind::kTriangle) ++triangles;
        else im->solids.push_back(static_cast<std::uint32_t>(i));
    }
    im->lo = lo;
    im->hi = hi;
    // The normalised frame: centre of the box, scale the power of two at or above its half size.
    im->center = 0.5 * (lo + hi);
    double half = 0;
    for (int a = 0; a < 3; ++a) half = std::max(half, 0.5 * hi[a] - 0.5 * lo[a]);
    if (!(half > 0)) half = std::max({std::fabs(lo.x), std::fabs(lo.y), std::fabs(lo.z), 1e-300});
    int exponent = 0;
    std::frexp(half, &exponent);  // half < 2^exponent
    im->scale = std::ldexp(1.0, exponent);
    im->inv_scale = std::ldexp(1.0, -exponent);

    im->device = rtcNewDevice(kDeviceConfig);
    if (!im->device) throw std::runtime_error("Embree: no device (" + std::string(kDeviceConfig) + ")");
    rtcSetDeviceErrorFunction(im->device, record_error, im.get());
    rtcSetDeviceMemoryMonitorFunction(im->device, count_bytes, im.get());
    im->scene = rtcNewScene(im->device);
    rtcSetSceneFlags(im->scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(im->scene, RTC_BUILD_QUALITY_MEDIUM);
    if (triangles > 0) {
        RTCGeometry g = rtcNewGeometry(im->device, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * triangles));
        auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), prims.size()));
        if (!vb || !ib) {
            rtcReleaseGeometry(g);
            check(*im);
            throw std::bad_alloc();
        }
        unsigned v = 0;
        for (std::size_t i = 0; i < prims.size(); ++i) {
            const Occluder& p = prims[i];
            if (p.kind != OccluderKind::kTriangle) {
                ib[3 * i] = ib[3 * i + 1] = ib[3 * i + 2] = kNoVertex;  // not a triangle: Embree skips it
                continue;
            }
            // Grown by kGrow about the centroid (in the normalised frame, then rounded to float).
            const Vec3 c[3] = {im->inv_scale * (p.v0 - im->center), im->inv_scale * (p.v1 - im->center), im->inv_scale * (p.v2 - im->center)};
            const Vec3 g = (1.0 / 3.0) * (c[0] + c[1] + c[2]);
            for (const Vec3& x : c) {
                const double len = length(x - g);
                const Vec3 y = len > 0 ? x + (kGrow / len) * (x - g) : x;
                float* out = vb + 3 * static_cast<std::size_t>(v);
                out[0] = static_cast<float>(y.x);
                out[1] = static_cast<float>(y.y);
                out[2] = static_cast<float>(y.z);
                ib[3 * i + (v % 3)] = v;
                ++v;
            }
        }
        rtcSetGeometryIntersectFilterFunction(g, triangle_filter);
        rtcSetGeometryOccludedFilterFunction(g, triangle_filter);
        rtcCommitGeometry(g);
        im->tri_geom = rtcAttachGeometry(im->scene, g);
        rtcReleaseGeometry(g);
    }
    if (!im->solids.empty()) {
        RTCGeometry g = rtcNewGeometry(im->device, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(g, static_cast<unsigned>(im->solids.size()));
        rtcSetGeometryUserData(g, im.get());
        rtcSetGeometryBoundsFunction(g, solid_bounds, im.get());
        rtcSetGeometryIntersectFunction(g, solid_intersect);
        rtcSetGeometryOccludedFunction(g, solid_occluded);
        rtcCommitGeometry(g);
        rtcAttachGeometry(im->scene, g);
        im->solid_scene = rtcNewScene(im->device);
        rtcSetSceneFlags(im->solid_scene, RTC_SCENE_FLAG_ROBUST);
        rtcAttachGeometry(im->solid_scene, g);
        rtcReleaseGeometry(g);
        rtcCommitScene(im->solid_scene);
    }
    rtcCommitScene(im->scene);
    check(*im);
    // root_bounds: the box moved out by a relative 1e-9 per side (conservative for callers that
    // scale offsets by the scene's extent).
    for (int a = 0; a < 3; ++a) {
        const double l = lo[a], h = hi[a];
        const double pad = 1e-9 * std::max({h - l, std::abs(l), std::abs(h), 1e-300});
        (a == 0 ? lo_.x : a == 1 ? lo_.y : lo_.z) = l - pad;
        (a == 0 ? hi_.x : a == 1 ? hi_.y : hi_.z) = h + pad;
    }
    prims_ = im->prims.data();
    count_ = im->prims.size();
    impl_ = std::move(im);
}

std::size_t OccluderBvh::memory_bytes() const {
    if (!impl_) return 0;
    return impl_->prims.capacity() * sizeof(Occluder) + impl_->solids.capacity() * sizeof(std::uint32_t) +
           static_cast<std::size_t>(std::max<std::int64_t>(0, impl_->embree_bytes.load(std::memory_order_relaxed)));
}

bool OccluderBvh::occluded(Vec3 o, Vec3 d, double t_min, double t_max) const {
    if (!impl_) return false;
    Query q;
    RTCRay ray;
    if (!setup(*impl_, o, d, t_min, t_max, q, ray)) return false;
    q.nearest = false;
    rtcOccluded1(impl_->scene, &q.ctx, &ray);
    return ray.tfar < 0;
}

RayHit OccluderBvh::nearest(Vec3 o, Vec3 d, double t_min, double t_max) const {
    if (!impl_) return {};
    Query q;
    RTCRayHit rh;
    if (!setup(*impl_, o, d, t_min, t_max, q, rh.ray)) return {};
    q.nearest = true;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(impl_->scene, &q.ctx, &rh);
    return q.best;
}

bool OccluderBvh::inside_any_solid(Vec3 p) const {
    if (!impl_ || !impl_->solid_scene) return false;
    const Impl& im = *impl_;
    const double pad = kMargin * im.scale;  // outside the box by more than rounding: in no solid
    if (p.x < im.lo.x - pad || p.x > im.hi.x + pad || p.y < im.lo.y - pad || p.y > im.hi.y + pad || p.z < im.lo.z - pad ||
        p.z > im.hi.z + pad)
        return false;
    PointQuery pq{&im, p, {}, {}, false};
    float at[3];
    im.to_frame(p, at);
    RTCPointQuery query;
    query.x = at[0];
    query.y = at[1];
    query.z = at[2];
    query.radius = static_cast<float>(kMargin);
    query.time = 0.0f;
    RTCPointQueryContext ctx;
    rtcInitPointQueryContext(&ctx);
    rtcPointQuery(im.solid_scene, &query, &ctx, point_callback, &pq);
    return pq.found;
}

bool OccluderBvh::overlaps_box(Vec3 lo, Vec3 hi) const {
    if (!impl_) return false;
    const Impl& im = *impl_;
    // The part of [lo, hi] inside the scene's box (empty: nothing overlaps).
    const Vec3 a{std::max(lo.x, im.lo.x), std::max(lo.y, im.lo.y), std::max(lo.z, im.lo.z)};
    const Vec3 b{std::min(hi.x, im.hi.x), std::min(hi.y, im.hi.y), std::min(hi.z, im.hi.z)};
    if (!(a.x <= b.x && a.y <= b.y && a.z <= b.z)) return false;
    PointQuery pq{&im, {}, lo, hi, true};
    float at[3];
    im.to_frame(0.5 * (a + b), at);
    RTCPointQuery query;
    query.x = at[0];
    query.y = at[1];
    query.z = at[2];
    query.radius = float_up(0.5 * length(b - a) * im.inv_scale + kMargin);
    query.time = 0.0f;
    RTCPointQueryContext ctx;
    rtcInitPointQueryContext(&ctx);
    rtcPointQuery(im.scene, &query, &ctx, point_callback, &pq);
    return pq.found;
}

}  // namespace zhc
