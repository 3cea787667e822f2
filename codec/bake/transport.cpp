#include "codec/bake/transport.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "codec/bake/scene.h"

namespace zhc {

// Counter-based random numbers: SplitMix64 (Steele, Lea and Flood 2014) over a state seeded from
// (probe, batch); the sequence depends on nothing else.
struct PathTracer::Rng {
    std::uint64_t state;
    Rng(std::uint64_t probe, std::uint64_t batch) : state(mix(probe * 0x9E3779B97F4A7C15ull ^ mix(batch + 0x632BE59BD9B4E019ull))) {}
    static std::uint64_t mix(std::uint64_t z) {
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    // Uniform in [0, 1) with 53 random bits.
    double uniform() {
        state += 0x9E3779B97F4A7C15ull;
        return double(mix(state) >> 11) * (1.0 / 9007199254740992.0);
    }
};

namespace {

bool any_positive(Rgb c) { return c.r > 0 || c.g > 0 || c.b > 0; }

// Normalised irradiance (constant radiance 1 -> 1) of SH3 radiance acc for unit normal n: band
// scales 1, 2/3, 1/4; luminance weights of Rec. 709.
double sh_irradiance_luminance(const double sh[27], Vec3 n) {
    const auto y = sh3_basis(n);
    double rgb[3] = {0, 0, 0};
    for (int i = 0; i < 9; ++i) {
        const double a = i == 0 ? 1.0 : (i < 4 ? 2.0 / 3.0 : 0.25);
        for (int k = 0; k < 3; ++k) rgb[k] += a * y[static_cast<size_t>(i)] * sh[i * 3 + k];
    }
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
}

const Vec3 kAxes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

// The largest albedo a material can have anywhere (texels are at most 1).
double albedo_bound(const SceneMaterial& m, int k) {
    if (!m.textured()) return m.albedo[k];
    return m.metal_rough_texture >= 0 ? m.base_factor[k] : m.albedo[k];
}
bool may_reflect(const SceneMaterial& m) {
    return albedo_bound(m, 0) > 0 || albedo_bound(m, 1) > 0 || albedo_bound(m, 2) > 0;
}

// Texel index i on an axis of n texels, wrapped.
std::int64_t wrap_index(double i, std::int64_t n, TextureWrap w) {
    const double dn = double(n);
    switch (w) {
        case TextureWrap::kClamp: return static_cast<std::int64_t>(std::clamp(i, 0.0, dn - 1));
        case TextureWrap::kMirror: {
            const double m = std::max(0.0, i - 2 * dn * std::floor(i / (2 * dn)));  // in [0, 2n) up to rounding
            const auto k = std::min(static_cast<std::int64_t>(m), 2 * n - 1);
            return k < n ? k : 2 * n - 1 - k;
        }
        default: {
            const double m = std::max(0.0, i - dn * std::floor(i / dn));
            return std::min(static_cast<std::int64_t>(m), n - 1);
        }
    }
}

}  // namespace

void sample_texture(const SceneTexture& t, double u, double v, double rgb[3]) {
    rgb[0] = rgb[1] = rgb[2] = 1;
    if (t.width == 0 || t.height == 0 || t.texels.size() < std::size_t(t.width) * t.height * 3) return;
    if (!std::isfinite(u)) u = 0;
    if (!std::isfinite(v)) v = 0;
    // Far outside [0, 1] a float UV has no fractional bits left: keep the arithmetic in range.
    u = std::clamp(u, -1e9, 1e9);
    v = std::clamp(v, -1e9, 1e9);
    const std::int64_t w = t.width, h = t.height;
    auto texel = [&](std::int64_t x, std::int64_t y, int k) { return double(t.texels[static_cast<std::size_t>((y * w + x) * 3 + k)]); };
    if (t.nearest) {
        const std::int64_t x = wrap_index(std::floor(u * double(w)), w, t.wrap_s), y = wrap_index(std::floor(v * double(h)), h, t.wrap_t);
        for (int k = 0; k < 3; ++k) rgb[k] = texel(x, y, k);
        return;
    }
    const double fx = u * double(w) - 0.5, fy = v * double(h) - 0.5;
    const double x0 = std::floor(fx), y0 = std::floor(fy);
    const double ax = fx - x0, ay = fy - y0;
    const std::int64_t xa = wrap_index(x0, w, t.wrap_s), xb = wrap_index(x0 + 1, w, t.wrap_s);
    const std::int64_t ya = wrap_index(y0, h, t.wrap_t), yb = wrap_index(y0 + 1, h, t.wrap_t);
    for (int k = 0; k < 3; ++k) {
        const double top = (1 - ax) * texel(xa, ya, k) + ax * texel(xb, ya, k);
        const double bottom = (1 - ax) * texel(xa, yb, k) + ax * texel(xb, yb, k);
        rgb[k] = (1 - ay) * top + ay * bottom;
    }
}

bool scene_has_transport(const Scene& s) {
    if (s.transport.max_bounces <= 0 || s.materials.empty()) return false;
    bool reflects = false, emits = false;
    for (const SceneMaterial& m : s.materials) {
        reflects = reflects || may_reflect(m);
        emits = emits || any_positive(m.emission);
    }
    if (!reflects && !emits) return false;
    // Is some occluder made of a reflecting or emitting material?
    bool used = false;
    for (const Occluder& o : s.occluders) {
        std::uint32_t mi = o.material;
        if (is_surface(mi)) mi = (mi & ~kSurfaceBit) < s.surfaces.size() ? s.surfaces[mi & ~kSurfaceBit].material : kNoMaterial;
        if (mi < s.materials.size()) {
            const SceneMaterial& m = s.materials[mi];
            if (may_reflect(m) || any_positive(m.emission)) {
                used = true;
                break;
            }
        }
    }
    if (!used) return false;
    return emits || !s.lights.empty() || s.sky || s.environment;
}

bool PathTracer::shade(const Occluder& occ, Vec3 x, double albedo[3], double emission[3]) const {
    std::uint32_t mi = occ.material;
    const SurfaceUv* uv = nullptr;
    if (is_surface(mi)) {
        uv = &scene_.surfaces[mi & ~kSurfaceBit];
        mi = uv->material;
    }
    if (mi >= materials_.size()) return false;
    const SceneMaterial& m = materials_[mi];
    for (int k = 0; k < 3; ++k) {
        albedo[k] = m.albedo[k];
        emission[k] = m.emission[k];
    }
    if (!uv || !m.textured()) return true;
    // Barycentric coordinates of x in (v0, v1, v2), then the UV there.
    const Vec3 e1 = occ.v1 - occ.v0, e2 = occ.v2 - occ.v0, q = x - occ.v0;
    const double d00 = dot(e1, e1), d01 = dot(e1, e2), d11 = dot(e2, e2), d20 = dot(q, e1), d21 = dot(q, e2);
    const double den = d00 * d11 - d01 * d01;
    double b1 = 1.0 / 3, b2 = 1.0 / 3;
    if (den > 0) {
        b1 = (d11 * d20 - d01 * d21) / den;
        b2 = (d00 * d21 - d01 * d20) / den;
    }
    const double b0 = 1 - b1 - b2;
    const double u = b0 * uv->uv[0][0] + b1 * uv->uv[1][0] + b2 * uv->uv[2][0];
    const double v = b0 * uv->uv[0][1] + b1 * uv->uv[1][1] + b2 * uv->uv[2][1];
    // Texture t at the UV mapped by its transform.
    auto sample = [&](int t, const SceneMaterial::UvTransform& x, double rgb[3]) {
        const double su = double(x[0]) * u + double(x[1]) * v + double(x[2]), sv = double(x[3]) * u + double(x[4]) * v + double(x[5]);
        sample_texture(scene_.textures[static_cast<std::size_t>(t)], su, sv, rgb);
    };
    if (m.base_texture >= 0 || m.metal_rough_texture >= 0) {
        double base[3] = {1, 1, 1}, metal = m.metallic;
        if (m.base_texture >= 0) sample(m.base_texture, m.base_uv, base);
        if (m.metal_rough_texture >= 0) {
            double mr[3];
            sample(m.metal_rough_texture, m.metal_rough_uv, mr);
            metal *= mr[2];
        }
        for (int k = 0; k < 3; ++k) albedo[k] = double(m.base_factor[k]) * base[k] * (1.0 - metal);
    }
    if (m.emissive_texture >= 0) {
        double e[3];
        sample(m.emissive_texture, m.emissive_uv, e);
        for (int k = 0; k < 3; ++k) emission[k] *= e[k];
    }
    return true;
}

PathTracer::PathTracer(const Scene& scene, const OccluderBvh& bvh) : scene_(scene), bvh_(bvh), materials_(scene.materials), limits_(scene.transport) {
    if (scene.environment) {
        const SceneEnvironment& env = *scene.environment;
        Sh3Radiance sh = env.projected;
        if (env.rotation_rad != 0) sh = rotate(sh, rotation_axis_angle({0, 0, 1}, env.rotation_rad));
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) env_[i * 3 + k] = double(sh[i][k]) * env.intensity;
        has_env_ = true;
    }
    for (const SceneLight& l : scene.lights) {
        Light q;
        q.kind = static_cast<int>(l.kind);
        q.position = l.position;
        q.center = l.center;
        q.radius = l.radius;
        q.shadows = l.shadows;
        for (int k = 0; k < 3; ++k) q.rgb[k] = l.color[k];
        switch (l.kind) {
            case LightKind::kDirectional:
                q.direction = normalize_or(l.direction, {0, 0, 1});
                if (l.angular_radius_rad > 0) {
                    const double s = std::sin(l.angular_radius_rad);
                    q.cos_sigma = std::cos(l.angular_radius_rad);
                    for (int k = 0; k < 3; ++k) q.rgb[k] = l.color[k] / (s * s);  // cone radiance
                }
                break;
            case LightKind::kSpot:
                q.direction = normalize_or(l.direction, {0, 0, -1});
                q.cos_outer = std::cos(l.outer_angle_rad);
                q.cos_inner = std::cos(l.inner_angle_rad);
                break;
            case LightKind::kHemisphere:
                q.direction = normalize_or(l.direction, {0, 0, 1});
                hemispheres_.push_back(q);
                continue;
            default: break;
        }
        lights_.push_back(q);
    }
    double a_max = 0;
    for (const SceneMaterial& m : materials_)
        for (int k = 0; k < 3; ++k) a_max = std::max(a_max, albedo_bound(m, k));
    energy_left_ = std::pow(a_max, limits_.max_bounces);
    // Surface offset: relative to the scene's extent (rounding of hit points is ~1e-16 of it).
    double extent = 1.0;
    if (!bvh.empty()) {
        Vec3 lo, hi;
        bvh.root_bounds(&lo, &hi);
        for (int a = 0; a < 3; ++a) extent = std::max({extent, std::fabs(lo[a]), std::fabs(hi[a])});
    }
    eps_ = 1e-9 * extent;
}

void PathTracer::distant_radiance(Vec3 d, double rgb[3]) const {
    rgb[0] = rgb[1] = rgb[2] = 0;
    if (has_env_) {
        const auto y = sh3_basis(d);
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) rgb[k] += env_[i * 3 + k] * y[static_cast<size_t>(i)];
    }
    if (scene_.sky) {
        double s[3];
        sky_radiance(*scene_.sky, d, s);
        for (int k = 0; k < 3; ++k) rgb[k] += s[k];
    }
    for (const Light& h : hemispheres_)
        if (dot(d, h.direction) > 0)
            for (int k = 0; k < 3; ++k) rgb[k] += h.rgb[k];
}

// Irradiance (true, not normalised) at x with normal n from the listed lights, one sample each.
void PathTracer::light_irradiance(Vec3 x, Vec3 n, Rng& rng, double E[3], std::uint64_t* rays) const {
    const Vec3 o = x + eps_ * n;
    for (const Light& l : lights_) {
        double scale = 0;
        Vec3 dir;
        double t_max = std::numeric_limits<double>::infinity();
        const auto kind = static_cast<LightKind>(l.kind);
        if (kind == LightKind::kPoint || kind == LightKind::kSpot) {
            const Vec3 v = l.position - o;
            const double d2 = dot(v, v);
            if (!(d2 > 0)) continue;
            const double d = std::sqrt(d2);
            dir = (1.0 / d) * v;
            const double c = dot(n, dir);
            if (c <= 0) continue;
            scale = c / d2;
            if (kind == LightKind::kSpot) {
                const double x0 = -dot(l.direction, dir);
                double a;
                if (l.cos_inner <= l.cos_outer) {
                    a = x0 >= l.cos_outer ? 1.0 : 0.0;
                } else {
                    const double t = std::clamp((x0 - l.cos_outer) / (l.cos_inner - l.cos_outer), 0.0, 1.0);
                    a = t * t * (3.0 - 2.0 * t);
                }
                scale *= a;
                if (scale == 0) continue;
            }
            t_max = d;
        } else {
            // Cone lights: the sun (a delta when its radius is 0) and sphere lights.
            Vec3 axis = l.direction;
            double cos_s = l.cos_sigma;
            if (kind == LightKind::kSphere) {
                const Vec3 v = l.center - o;
                const double d2 = dot(v, v), r2 = l.radius * l.radius;
                if (d2 <= r2) continue;  // a surface inside a sphere light: not lit by it
                const double d = std::sqrt(d2);
                axis = (1.0 / d) * v;
                cos_s = std::sqrt(1.0 - r2 / d2);
            }
            if (kind == LightKind::kDirectional && cos_s >= 1.0) {
                dir = axis;
                const double c = dot(n, dir);
                if (c <= 0) continue;
                scale = kPi * c;  // E = pi E_n cos for zhc's normalised irradiance E_n
            } else {
                const double z = 1.0 - rng.uniform() * (1.0 - cos_s), phi = 2.0 * kPi * rng.uniform();
                const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
                dir = frame_from_z(axis) * Vec3{r * std::cos(phi), r * std::sin(phi), z};
                const double c = dot(n, dir);
                if (c <= 0) continue;
                scale = 2.0 * kPi * (1.0 - cos_s) * c;  // L * solid angle * cos, one uniform sample
                if (kind == LightKind::kSphere) {
                    const Vec3 v = l.center - o;
                    const double b = dot(dir, v), disc = std::max(0.0, b * b - dot(v, v) + l.radius * l.radius);
                    t_max = b - std::sqrt(disc);
                }
            }
        }
        if (l.shadows) {
            ++*rays;
            if (bvh_.occluded(o, dir, 0.0, t_max)) continue;
        }
        for (int k = 0; k < 3; ++k) E[k] += scale * l.rgb[k];
    }
}

void PathTracer::path_radiance(Vec3 x, Vec3 d, std::uint32_t prim, Rng& rng, double L[3], ProbeStats& st) const {
    double T[3] = {1, 1, 1};
    L[0] = L[1] = L[2] = 0;
    for (int depth = 1;; ++depth) {
        const Occluder& occ = bvh_.primitive(prim);
        double albedo[3], emission[3];
        if (!shade(occ, x, albedo, emission)) return;  // absorbs everything, emits nothing
        const Vec3 n = surface_normal(occ, x, d);
        ++st.vertices;
        st.max_depth = std::max(st.max_depth, depth);
        for (int k = 0; k < 3; ++k) L[k] += T[k] * emission[k];
        if (!(albedo[0] > 0 || albedo[1] > 0 || albedo[2] > 0)) return;
        double E[3] = {0, 0, 0};
        light_irradiance(x, n, rng, E, &st.rays);
        for (int k = 0; k < 3; ++k) {
            L[k] += T[k] * albedo[k] / kPi * E[k];
            T[k] *= albedo[k];
        }
        if (depth >= limits_.max_bounces) {
            ++st.cut;
            return;
        }
        if (depth >= 3) {
            const double q = std::min(1.0, std::max({T[0], T[1], T[2]}));
            if (!(rng.uniform() < q)) return;
            for (double& t : T) t /= q;
        }
        // Cosine-distributed continuation (Malley: a uniform disc point lifted to the hemisphere).
        const double u1 = rng.uniform(), u2 = rng.uniform();
        const double r = std::sqrt(u1), phi = 2.0 * kPi * u2;
        const Vec3 w = frame_from_z(n) * Vec3{r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - u1))};
        const Vec3 o = x + eps_ * n;
        ++st.rays;
        const RayHit h = bvh_.nearest(o, w, 0.0, std::numeric_limits<double>::infinity());
        if (!h.hit) {
            double D[3];
            distant_radiance(w, D);
            for (int k = 0; k < 3; ++k) L[k] += T[k] * D[k];
            return;
        }
        const Occluder& next = bvh_.primitive(h.prim);
        if (h.back && next.kind != OccluderKind::kTriangle) return;  // inside a solid: no light
        x = o + h.t * w;
        d = w;
        prim = h.prim;
    }
}

PathTracer::ProbeStats PathTracer::trace_probe(Vec3 p, std::uint64_t probe_index, const double closed_form[27], double acc[27]) const {
    ProbeStats st;
    const int min_batches = std::max(1, (limits_.min_rays + kTransportBatch - 1) / kTransportBatch);
    const int max_batches = std::max({2, min_batches, (limits_.max_rays + kTransportBatch - 1) / kTransportBatch});
    double sum[27] = {};
    // Per batch, the six axis irradiances (luminance) of that batch alone, for the noise estimate.
    double axis_sum[6] = {}, axis_sq[6] = {};
    double closed_axes = 0;
    for (const Vec3& a : kAxes) closed_axes += sh_irradiance_luminance(closed_form, a) / 6.0;
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    int batches = 0;
    for (; batches < max_batches; ++batches) {
        Rng rng(probe_index, static_cast<std::uint64_t>(batches));
        const double phi0 = 2.0 * kPi * rng.uniform();
        double batch[27] = {};
        for (int k = 0; k < kTransportBatch; ++k) {
            // Equal-area band k of z (one jittered sample), golden-angle azimuth.
            const double z = 1.0 - 2.0 * (k + rng.uniform()) / kTransportBatch;
            const double r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = phi0 + golden * k;
            const Vec3 w{r * std::cos(phi), r * std::sin(phi), z};
            ++st.paths;
            ++st.rays;
            const RayHit h = bvh_.nearest(p, w, 1e-9, std::numeric_limits<double>::infinity());
            if (!h.hit) continue;
            if (h.back && bvh_.primitive(h.prim).kind != OccluderKind::kTriangle) continue;  // probe inside a solid
            double L[3];
            path_radiance(p + h.t * w, w, h.prim, rng, L, st);
            const auto y = sh3_basis(w);
            for (int i = 0; i < 9; ++i)
                for (int c = 0; c < 3; ++c) batch[i * 3 + c] += L[c] * y[static_cast<size_t>(i)];
        }
        double scaled[27];
        for (int i = 0; i < 27; ++i) {
            sum[i] += batch[i];
            scaled[i] = batch[i] * (4.0 * kPi / kTransportBatch);
        }
        for (int a = 0; a < 6; ++a) {
            const double e = sh_irradiance_luminance(scaled, kAxes[a]);
            axis_sum[a] += e;
            axis_sq[a] += e * e;
        }
        const int nb = batches + 1;
        if (nb < std::max(2, min_batches)) continue;
        // Standard error of the mean of nb batch estimates, largest over the axes, relative to
        // the probe's mean axis irradiance (closed form plus this estimate).
        double se = 0, mean_axes = closed_axes;
        for (int a = 0; a < 6; ++a) {
            const double mean = axis_sum[a] / nb;
            const double var = std::max(0.0, (axis_sq[a] - nb * mean * mean) / (nb - 1));
            se = std::max(se, std::sqrt(var / nb));
            mean_axes += mean / 6.0;
        }
        st.noise = mean_axes > 0 ? se / mean_axes : 0.0;
        if (st.noise <= limits_.max_noise) {
            ++batches;
            break;
        }
    }
    const double w = 4.0 * kPi / (double(batches) * kTransportBatch);
    for (int i = 0; i < 27; ++i) acc[i] += w * sum[i];
    return st;
}

}  // namespace zhc
