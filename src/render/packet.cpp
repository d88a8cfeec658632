// Path tracing of four samples at once, their paths in the lanes of SIMD registers (AVX2 where
// the CPU has it). Casting rays, hit records, Sobol numbers, the light choice, the `brief`
// and `cone` light samples, every material's scattering, throughput and Russian roulette
// run lane-wise, as copies of the one-path routines, operation for operation; the other
// light samples, emission weights and other estimators' numbers run per lane through the
// same functions as one path (path.h). So every path is the one trace_sample gives, up to
// rounding. docs/performance.md ("Paths in lanes" and after) has what it buys.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/sampling.h"
#include "render/lanes.h"
#include "render/path.h"

namespace kr {

namespace {

using kr::select;  // lanes.h's, beside the three-vector one below

constexpr double kInf = std::numeric_limits<double>::infinity();
// A one-leaf scene has at most 16 spheres, so at most 16 materials are used.
constexpr size_t kMaxPacketSpheres = 16, kMaxPacketMaterials = 16;

KR_LANES v4d abs_lanes(v4d x) { return select(x < 0, -x, x); }
KR_LANES v4l sign_bit(v4d x) {  // all ones where x is negative (-0 included)
    v4l bits;
    __builtin_memcpy(&bits, &x, sizeof bits);
    return bits < 0;
}

// Four vectors, one per lane.
struct V3 {
    v4d x, y, z;
};
KR_LANES V3 operator+(const V3& a, const V3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
KR_LANES V3 operator-(const V3& a, const V3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
KR_LANES V3 operator*(const V3& a, v4d s) { return {a.x * s, a.y * s, a.z * s}; }
KR_LANES V3 operator*(const V3& a, const V3& b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
KR_LANES V3 operator-(const V3& a) { return {-a.x, -a.y, -a.z}; }
KR_LANES v4d dot(const V3& a, const V3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
KR_LANES V3 select(v4l mask, const V3& a, const V3& b) {
    return {select(mask, a.x, b.x), select(mask, a.y, b.y), select(mask, a.z, b.z)};
}
KR_LANES Vec3 lane(const V3& v, int k) { return {v.x[k], v.y[k], v.z[k]}; }
KR_LANES void set_lane(V3& v, int k, const Vec3& value) { v.x[k] = value.x, v.y[k] = value.y, v.z[k] = value.z; }

// ---- Lane-wise copies of the one-path routines, operation for operation ----

// sin_cos_turns (core/sampling.h): the same reduction and polynomials, then the quarter
// turns lane-wise.
KR_LANES void sin_cos_turns_lanes(v4d t, v4d& sin_out, v4d& cos_out) {
    v4d quarter, s, c;
    sin_cos_eighth_turn(t, quarter, s, c);
    const v4l k = __builtin_convertvector(quarter, v4l) & 3;
    const v4l odd = (k & 1) != 0;
    const v4d sin_mag = select(odd, c, s), cos_mag = select(odd, s, c);
    sin_out = select((k & 2) != 0, -sin_mag, sin_mag);
    cos_out = select(((k + 1) & 2) != 0, -cos_mag, cos_mag);
}

// sample_cosine_hemisphere (core/sampling.cpp): the concentric disk lifted to the hemisphere.
KR_LANES V3 cosine_hemisphere_lanes(v4d u1, v4d u2) {
    const v4d a = 2.0 * u1 - 1.0, b = 2.0 * u2 - 1.0;
    const v4l centre = (a == 0) & (b == 0);
    const v4l a_major = abs_lanes(a) > abs_lanes(b);
    const v4d r = select(a_major, a, b);
    const v4d ratio = select(a_major, b, a) / r;
    const v4d turns = select(a_major, 0.125 * ratio, 0.25 - 0.125 * ratio);
    v4d s, c;
    sin_cos_turns_lanes(turns, s, c);
    const v4d x = select(centre, v4d{}, r * c), y = select(centre, v4d{}, r * s);
    const v4d one_minus = 1.0 - x * x - y * y;
    return {x, y, sqrt_lanes(select(one_minus > 0, one_minus, v4d{}))};
}

// Frame::from_normal(n).to_world(local) (core/math.h).
KR_LANES V3 to_world_lanes(const V3& n, const V3& local) {
    const v4d sign = select(sign_bit(n.z), splat(-1.0), splat(1.0));
    const v4d a = -1.0 / (sign + n.z);
    const v4d b = n.x * n.y * a;
    const V3 s{1 + sign * n.x * n.x * a, sign * b, -sign * n.x};
    const V3 t{b, sign + n.y * n.y * a, -n.y};
    return s * local.x + t * local.y + n * local.z;
}

// A sphere as the ray tests read it (trace_packet's table): the centre and the squared radius.
struct TestSphere {
    double x, y, z, r2;
};

// accepted_root (render_scene.cpp) of four rays against one sphere: the distance per lane, or
// +inf. The rays start at tmin = 0 (trace_packet checks). kShadow: segments with an end and a
// target sphere; closest-hit rays have neither. Where q = 0 the roots come out as +-inf, NaN
// and 0, none of which is accepted, as accepted_root rejects that case; where disc < 0 the
// square root is NaN and the lane is rejected too.
template <bool kShadow>
KR_LANES v4d sphere_lanes(const V3& o, const V3& d, v4l from, v4l into, v4d tmax, v4l to, const TestSphere& sphere,
                        int64_t id) {
    const double r2 = sphere.r2;
    const V3 f{o.x - sphere.x, o.y - sphere.y, o.z - sphere.z};
    const v4d b = dot(f, d);
    const V3 p{f.x - b * d.x, f.y - b * d.y, f.z - b * d.z};
    const v4d disc = r2 - dot(p, p);
    const v4d c = dot(f, f) - r2;
    const v4l origin = from == id;
    // Most spheres miss every lane: the line passes them by, or they lie behind an origin
    // outside them, or (shadow rays) they are the target or begin beyond the segment's end
    // (from outside, the near root is at least c / (2 |b|), as in accel.cpp). Then the square
    // root and division are skipped.
    v4l candidate = (disc >= 0) & ~((c > 0) & (b > 0) & ~origin);
    if constexpr (kShadow) {
        constexpr double kMargin = 16 * std::numeric_limits<double>::epsilon();
        const v4d f2 = dot(f, f);
        const v4l beyond = ~origin & (c > kMargin * (f2 + r2)) & (c > (-2.0 * (1.0 + kMargin)) * b * tmax);
        candidate &= ~beyond & (to != id);
    }
    if (!any_lane(candidate)) return splat(kInf);
    const v4d root = sqrt_lanes(disc);
    const v4d q = -b - select(sign_bit(b), -root, root);  // copysign(root, b)
    const v4d t0 = c / q;
    const v4l t0_first = t0 < q;
    const v4d t_near = select(t0_first, t0, q), t_far = select(t0_first, q, t0);
    v4l near_ok = ~origin & (t_near > 0) & candidate, far_ok = (t_far > 0) & (~origin | into) & candidate;
    if constexpr (kShadow) {
        const v4d f_l1 = abs_lanes(f.x) + abs_lanes(f.y) + abs_lanes(f.z);
        const v4d end = select(tmax < kInf, tmax - kSegmentEndTolerance * (f_l1 + tmax), tmax);
        near_ok &= t_near <= end;
        far_ok &= t_far <= end;
    }
    return select(near_ok, t_near, select(far_ok, t_far, splat(kInf)));
}

// sample_sphere_light (light.cpp) for a shading point outside the light, lane-wise, for the
// `brief` and `cone` strategies. `valid`: lanes with a sample.
struct LightLanes {
    V3 wi;
    v4d distance, pdf, mis_pdf;
    v4l valid;
};
KR_LANES LightLanes sample_light_lanes(LightSampling strategy, const V3& centre, v4d radius, const V3& p, v4d u1,
                                     v4d u2, v4l lanes) {
    LightLanes out;
    const V3 to_centre = centre - p;
    const v4d d2 = dot(to_centre, to_centre);
    const v4d r2 = radius * radius;
    const v4d d = sqrt_lanes(d2);
    if (strategy == LightSampling::cone) {
        // cone_one_minus_cos, sample_uniform_cone, then the distance to the near side.
        const v4d sin2_max = r2 / d2;
        const v4d one_minus_sin2 = 1.0 - sin2_max;
        const v4d cos_max = sqrt_lanes(select(0.0 < one_minus_sin2, one_minus_sin2, v4d{}));
        const v4d one_minus_cos_max = sin2_max / (1.0 + cos_max);
        const v4d one_minus_cos = u1 * one_minus_cos_max;
        const v4d sin2 = one_minus_cos * (2.0 - one_minus_cos);
        const v4d sin_theta = sqrt_lanes(select(0.0 < sin2, sin2, v4d{}));
        v4d s, c;
        sin_cos_turns_lanes(u2, s, c);
        const V3 local{sin_theta * c, sin_theta * s, 1.0 - one_minus_cos};
        out.wi = to_world_lanes(to_centre * (1.0 / d), local);
        const v4d local_sin2 = local.x * local.x + local.y * local.y;
        const v4d inside = r2 - d2 * local_sin2;
        out.distance = d * local.z - sqrt_lanes(select(0.0 < inside, inside, v4d{}));
        out.pdf = 1.0 / (2.0 * kPi * one_minus_cos_max);
        out.mis_pdf = out.pdf;
        out.valid = lanes & (out.distance > 0);
        return out;
    }
    // brief: BriefProposal's mixture; the rare log-uniform branch per lane, and the logarithm
    // too where a lane's ratio is outside log_normal_positive's range.
    const v4d a = d * d + radius * radius, b = 2 * d * radius, gap = d - radius;
    const v4d ratio = a / (gap * gap);
    const v4l normal = (ratio >= kSmallestNormal) & (ratio <= kLargestFinite);
    v4d v_max = select(lanes, log_normal_positive<v4d, v4u>(select(normal, ratio, splat(1.0))), v4d{});
    if (any_lane(lanes & ~normal))
        for (int k = 0; k < 4; ++k)
            if (lanes[k] && !normal[k]) v_max[k] = std::log(ratio[k]);
    const v4d mix = 1.0 + v_max * v_max * v_max;
    const v4d alpha = 1.0 / mix;
    const v4d x = u1 * mix;
    v4d cos_axis = sqrt_lanes(select(x < 1, x, v4d{}));
    const v4l log_part = lanes & ~(x < 1);
    if (any_lane(log_part))
        for (int k = 0; k < 4; ++k)
            if (log_part[k]) {
                const double t = (x[k] - 1) / (v_max[k] * v_max[k] * v_max[k]);
                cos_axis[k] = std::clamp(-a[k] * std::expm1(-t * v_max[k]) / b[k], 0.0, 1.0);
            }
    const v4d one_minus = 1.0 - cos_axis * cos_axis;
    const v4d sin_axis = sqrt_lanes(select(0.0 < one_minus, one_minus, v4d{}));
    v4d sin_phi, cos_phi;
    sin_cos_turns_lanes(u2, sin_phi, cos_phi);
    const V3 axis = (-to_centre) * (1.0 / d);
    const V3 n = to_world_lanes(axis, V3{sin_axis * cos_phi, sin_axis * sin_phi, cos_axis});
    const V3 w = (centre + n * radius) - p;
    const v4d dist2 = dot(w, w);
    const v4d dist = sqrt_lanes(dist2);
    out.valid = lanes & (dist > 0) & (cos_axis > 0);
    out.wi = w * (1.0 / dist);
    out.distance = dist;
    const v4d area_density_dist2 = alpha * (2 * cos_axis * dist2 + v_max * v_max * b) / (2 * kPi * r2);
    out.pdf = area_density_dist2 / cos_axis;
    const v4d cos_light = -dot(n, out.wi);
    const v4l visible_cap = (cos_axis * d > radius) & (cos_light > 0);
    out.mis_pdf = select(visible_cap, area_density_dist2 / cos_light, v4d{});
    return out;
}

// The five numbers of a path vertex (Sampler::next_vertex) of four Sobol samplers at once:
// their dimensions d (light choice), d + 1 (light point), d + 2 (lobe), d + 3 (BSDF
// direction) and d + 4 (roulette), each lane at its own d. Two dimensions share a register of
// eight words. The per-lane part keeps the numbers its vertex reads, as the one-path sampler
// draws only those; the lobe is drawn only where some lane reads it.
typedef uint32_t v4w __attribute__((vector_size(16)));  // four 32-bit words
typedef uint32_t v8w __attribute__((vector_size(32)));  // eight: two dimensions of four lanes
struct VertexLanes {
    v4d light_pick, light_x, light_y, lobe, bsdf_x, bsdf_y, roulette;
};
KR_LANES v4d unit_lanes(v4w fraction) {  // Sampler::to_unit, exactly: the words convert exactly
    typedef int32_t v4i __attribute__((vector_size(16)));
    const v4i centred = v4i(fraction ^ 0x80000000u);  // AVX2 converts signed words only
    return (__builtin_convertvector(centred, v4d) + 2147483648.5) * 0x1.0p-32;
}
KR_LANES v8w pair(v4w low, v4w high) { return __builtin_shufflevector(low, high, 0, 1, 2, 3, 4, 5, 6, 7); }
KR_LANES v4d unit_low(v8w words) { return unit_lanes(__builtin_shufflevector(words, words, 0, 1, 2, 3)); }
KR_LANES v4d unit_high(v8w words) { return unit_lanes(__builtin_shufflevector(words, words, 4, 5, 6, 7)); }
KR_LANES VertexLanes sobol_vertex_lanes(v4w key, v4w index_reversed, v4w d, bool lobe) {
    VertexLanes v;
    const v8w key2 = pair(key, key), index2 = pair(index_reversed, index_reversed);
    const SobolDimension<v8w> light_bsdf(key2, index2, pair(d + 1, d + 3));
    const v8w x = light_bsdf.x(), y = light_bsdf.y();
    v.light_x = unit_low(x), v.bsdf_x = unit_high(x);
    v.light_y = unit_low(y), v.bsdf_y = unit_high(y);
    const v8w pick_roulette = SobolDimension<v8w>(key2, index2, pair(d, d + 4)).x();
    v.light_pick = unit_low(pick_roulette), v.roulette = unit_high(pick_roulette);
    v.lobe = lobe ? unit_lanes(SobolDimension<v4w>(key, index_reversed, d + 2).x()) : v4d{};
    return v;
}

// What a path vertex's per-lane part (the light samples taken one lane at a time) hands to the
// lane-wise part. All zeros for a lane with nothing to do: the lane-wise part masks what such a
// lane computes (zeros, as one block of stores, cost a fifth of what member defaults did).
struct LaneVertex {
    bool shadow;
    Vec3 shadow_d, direct;
    double shadow_tmax;
    int64_t shadow_into, shadow_to;
};

// Lanes from one field of four records, or of the four records pointed to: the records are
// written one lane at a time (a vector stored to lane by lane would stall its next load).
template <class T>
KR_LANES const T& record(const T& r) { return r; }
template <class T>
KR_LANES const T& record(const T* r) { return *r; }
template <class R, class T>
KR_LANES v4d gather(const R (&v)[4], double T::*field) {
    return v4d{record(v[0]).*field, record(v[1]).*field, record(v[2]).*field, record(v[3]).*field};
}
template <class R, class T, class I>  // an index: int or int64_t
KR_LANES v4l gather(const R (&v)[4], I T::*field) {
    return v4l{record(v[0]).*field, record(v[1]).*field, record(v[2]).*field, record(v[3]).*field};
}
template <class R, class T>
KR_LANES v4l gather_mask(const R (&v)[4], bool T::*field) {
    return v4l{-int64_t(record(v[0]).*field), -int64_t(record(v[1]).*field), -int64_t(record(v[2]).*field),
               -int64_t(record(v[3]).*field)};
}
template <class R, class T>
KR_LANES V3 gather(const R (&v)[4], Vec3 T::*field) {
    const Vec3 &a = record(v[0]).*field, &b = record(v[1]).*field, &c = record(v[2]).*field, &d = record(v[3]).*field;
    return {v4d{a.x, b.x, c.x, d.x}, v4d{a.y, b.y, c.y, d.y}, v4d{a.z, b.z, c.z, d.z}};
}
template <class R, class T>
KR_LANES v4d gather_x(const R (&v)[4], Vec2 T::*field) {
    return v4d{(record(v[0]).*field).x, (record(v[1]).*field).x, (record(v[2]).*field).x, (record(v[3]).*field).x};
}
template <class R, class T>
KR_LANES v4d gather_y(const R (&v)[4], Vec2 T::*field) {
    return v4d{(record(v[0]).*field).y, (record(v[1]).*field).y, (record(v[2]).*field).y, (record(v[3]).*field).y};
}

// The lanes whose material is of the given type.
KR_LANES v4l of_type(const Material* const (&material)[4], MaterialType type) {
    return v4l{-int64_t(material[0]->type == type), -int64_t(material[1]->type == type),
               -int64_t(material[2]->type == type), -int64_t(material[3]->type == type)};
}

KR_LANES V3 normalize_lanes(const V3& a) {  // normalize (core/math.h): a / length(a)
    const v4d length = sqrt_lanes(dot(a, a));
    return {a.x / length, a.y / length, a.z / length};
}

// sample_material (material.cpp) for the mirror, glossy and dielectric materials: the same
// reflection, Fresnel split (split_dielectric, fresnel_dielectric, refract in core/math.h),
// choice of branch and perturbation by roughness (brief eq. 2), lane-wise. None of them has
// a smooth lobe, so there is no density.
struct ScatterLanes {
    V3 direction, weight;
    v4l ok;
};
KR_LANES ScatterLanes scatter_lanes(const Material* const (&material)[4], const V3& rho, v4l lanes, const V3& wi,
                                    const V3& ns, v4l front, v4d u_lobe, v4d u_x, v4d u_y) {
    const v4l specular = lanes & of_type(material, MaterialType::specular);
    const v4l glossy = lanes & of_type(material, MaterialType::glossy);
    const v4l translucent = lanes & of_type(material, MaterialType::translucent);
    const v4l dielectric = (lanes & of_type(material, MaterialType::dielectric)) | translucent;
    const v4d wi_n = dot(wi, ns);
    const V3 reflected = wi - ns * (2.0 * wi_n);
    v4l reflect_branch = ~dielectric;
    V3 direction = reflected;
    if (any_lane(dielectric)) {
        const v4d eta = gather(material, &Material::eta);
        const v4d eta_ratio = select(front, 1.0 / eta, eta);  // incident over transmitted
        const v4d eta2 = eta_ratio * eta_ratio;
        // fresnel_dielectric(-dot(wi, ns), eta_ratio), its cosine clamped to [0, 1]
        const v4d cos_i = -wi_n;
        const v4d cos_f = select(cos_i < 0, v4d{}, select(1.0 < cos_i, splat(1.0), cos_i));
        const v4d sin2_f = eta2 * (1.0 - cos_f * cos_f);
        const v4d cos_tf = sqrt_lanes(1.0 - sin2_f);
        const v4d r_s = (eta_ratio * cos_f - cos_tf) / (eta_ratio * cos_f + cos_tf);
        const v4d r_p = (cos_f - eta_ratio * cos_tf) / (cos_f + eta_ratio * cos_tf);
        v4d reflectance = select(sin2_f >= 1.0, splat(1.0), 0.5 * (r_s * r_s + r_p * r_p));
        // refract: total internal reflection where it fails, rounding included
        const v4d one_minus = 1.0 - cos_i * cos_i;
        const v4d sin2_t = eta2 * select(0.0 < one_minus, one_minus, v4d{});
        const v4l refracts = ~(sin2_t >= 1.0);
        const v4d cos_t = sqrt_lanes(1.0 - sin2_t);
        const V3 transmitted = normalize_lanes(wi * eta_ratio + ns * (eta_ratio * cos_i - cos_t));
        reflectance = select((reflectance < 1.0) & ~refracts, splat(1.0), reflectance);
        reflect_branch |= u_lobe < reflectance;
        direction = select(reflect_branch, reflected, transmitted);
    }
    const v4d beta = select(glossy | translucent, gather(material, &Material::roughness), v4d{});
    const v4l rough = beta > 0;
    if (any_lane(rough)) {
        // perturb_direction: sample_uniform_sphere times beta added, then normalised
        const v4d z = 1.0 - 2.0 * u_x;
        const v4d one_minus = 1.0 - z * z;
        const v4d r = sqrt_lanes(select(0.0 < one_minus, one_minus, v4d{}));
        v4d s, c;
        sin_cos_turns_lanes(u_y, s, c);
        direction = select(rough, normalize_lanes(direction + V3{r * c, r * s, z} * beta), direction);
    }
    ScatterLanes out;
    out.direction = direction;
    const v4d cos_out = dot(direction, ns);
    out.ok = specular | (reflect_branch ? v4l(cos_out > 0) : v4l(cos_out < 0));
    out.weight = rho;
    if (any_lane(dielectric))
        out.weight = select(dielectric,
                            select(reflect_branch, gather(material, &Material::rho_r), gather(material, &Material::rho_t)),
                            rho);
    return out;
}

// The four paths.
struct Paths {
    V3 o, d;  // the rays to cast next: from a surface or the camera, tmin 0, unbounded
    v4l from, into;
    v4l alive;
    v4l depth;  // of the vertex the next ray finds
    V3 throughput, L;
    v4l full_emission;  // PathHistory, lane-wise
    v4d last_bsdf_pdf;
    V3 last_p;
    v4l last_sphere;
    v4d primary_distance;
    v4w sobol_key, sobol_index, sobol_dimension;  // Sobol samplers' state (sobol_lanes)
    v4l rays;  // cast so far per path (masks are -1 where set, so subtracting one counts it)
};

// choose_light (integrator.cpp) lane-wise, for next-event estimation (not naive): the area
// light each lane's number picks, or -1 where it picks a point light. The same subtractions
// in the same order, so the same choices.
KR_LANES v4l area_choice_lanes(const RenderScene& scene, v4d u) {
    v4l undecided = ~v4l{};
    for (const PointLight& light : scene.point_lights) {
        undecided &= ~(u < light.select_prob);
        u = u - light.select_prob;
    }
    v4l area = v4l{} - 1;
    for (size_t i = 0; i < scene.area_lights.size(); ++i) {
        // The last light takes what rounding leaves above the total.
        const bool last = i + 1 == scene.area_lights.size();
        const v4l pick = undecided & ((u < scene.area_lights[i].select_prob) | (last ? ~v4l{} : v4l{}));
        area = pick ? v4l{} + int64_t(i) : area;
        undecided &= ~pick;
        u = u - scene.area_lights[i].select_prob;
    }
    return area;
}

// The closest sphere of each live lane's ray (its index and distance; -1 where none).
KR_LANES void closest_lanes(const TestSphere* spheres, size_t count, const Paths& paths, v4d& best, v4l& best_id) {
    best = splat(kInf);
    best_id = v4l{} - 1;
    for (size_t s = 0; s < count; ++s) {
        const v4d t = sphere_lanes<false>(paths.o, paths.d, paths.from, paths.into, v4d{}, v4l{}, spheres[s],
                                          int64_t(s));
        const v4l nearer = t < best;  // ties keep the lower index, as the linear scan does
        best = select(nearer, t, best);
        best_id = nearer ? v4l{} + int64_t(s) : best_id;
    }
    best_id = paths.alive ? best_id : v4l{} - 1;
}

// Whether anything blocks each shadow segment (lanes outside `cast` are left unblocked).
KR_LANES v4l occluded_lanes(const TestSphere* spheres, size_t count, const V3& o, const V3& d, v4l from, v4l into,
                          v4d tmax, v4l to, v4l cast) {
    v4l blocked = v4l{};
    for (size_t s = 0; s < count; ++s)
        blocked |= sphere_lanes<true>(o, d, from, into, tmax, to, spheres[s], int64_t(s)) < kInf;
    return blocked & cast;
}

// Where packets apply: path tracing on a scene our one-leaf BVH takes (up to 16 spheres), not
// the plain path. Embree's scenes and our trees cast rays one by one.
bool packets_apply(const RenderScene& scene, const RenderSettings& settings) {
    return settings.integrator != Integrator::wrt && !scene.linear_scan && scene.bvh.packets() &&
           scene.spheres.size() <= kMaxPacketSpheres && scene.materials.size() <= kMaxPacketMaterials;
}

}  // namespace

// `count` samples, four paths at a time, a bounce at a time: a lane whose path ends hands in
// its result and takes the next sample, so lanes stay busy while paths have different
// lengths. Camera rays as render_pass makes them (tmin 0, unbounded, from no sphere);
// trace_samples checks.
KR_CLONES void trace_packet(const RenderScene& scene, const RenderSettings& settings, const Ray* rays,
                            Sampler* const* samplers, int count, SampleResult* results) {
    const bool naive = settings.integrator == Integrator::pt_naive;
    const bool next_event_possible = scene.light_count() > 0;
    // Area-light samples lane-wise: the `brief` and `cone` strategies (the others per lane).
    const bool lane_lights = !naive && (settings.light_sampling == LightSampling::brief ||
                                        settings.light_sampling == LightSampling::cone);
    Paths paths{};  // no lane alive: each path's state is set where its lane starts it, below
    int lane_sample[4] = {-1, -1, -1, -1};  // the sample each lane traces
    Sampler* lane_sampler[4] = {};
    int next_sample = 0;
    // Sobol samplers draw their vertex numbers lane-wise; the others one lane at a time.
    bool sobol_lanes = true;
    for (int k = 0; k < count; ++k) sobol_lanes &= samplers[k]->sobol();

    // Per sphere: its material, the numbers a vertex on it reads (vertex_numbers_used, less
    // Russian roulette, which goes by depth alone), and (a bit each) whether it is a light's.
    unsigned numbers_used[kMaxPacketMaterials];
    for (size_t i = 0; i < scene.materials.size(); ++i)
        numbers_used[i] = vertex_numbers_used(scene, scene.materials[i], 0, kMaxDepth + 2);
    TestSphere test_spheres[kMaxPacketSpheres];
    const Material* sphere_material[kMaxPacketSpheres];
    unsigned sphere_use[kMaxPacketSpheres];
    int64_t emitters = 0;
    for (size_t s = 0; s < scene.spheres.size(); ++s) {
        const SphereGeom& geom = scene.spheres[s];
        test_spheres[s] = {geom.centre.x, geom.centre.y, geom.centre.z, geom.radius * geom.radius};
        const size_t material = size_t(scene.sphere_material[s]);
        sphere_material[s] = &scene.materials[material];
        sphere_use[s] = numbers_used[material];
        if (scene.sphere_light[s] >= 0) emitters |= int64_t(1) << s;
    }
    for (;;) {
        // Lanes whose path has ended hand in its result and start the next sample's. The new
        // paths' state is blended in lane-wise: stores into single lanes would stall the
        // vectors' next loads.
        v4l start{};
        const Ray* start_ray[4] = {rays, rays, rays, rays};
        for (int k = 0; k < 4; ++k) {
            if (paths.alive[k]) continue;
            if (lane_sample[k] >= 0) {
                SampleResult& r = results[lane_sample[k]];
                r.radiance = lane(paths.L, k);
                r.primary_distance = paths.primary_distance[k];
                r.rays = uint64_t(paths.rays[k]);
                lane_sample[k] = -1;
            }
            if (next_sample == count) continue;
            lane_sample[k] = next_sample;
            lane_sampler[k] = samplers[next_sample];
            start_ray[k] = &rays[next_sample];
            start[k] = -1;
            ++next_sample;
        }
        if (any_lane(start)) {
            const V3 zero{v4d{}, v4d{}, v4d{}};
            paths.o = select(start, gather(start_ray, &Ray::o), paths.o);
            paths.d = select(start, gather(start_ray, &Ray::d), paths.d);
            paths.alive |= start;
            paths.rays = start ? v4l{} : paths.rays;
            paths.depth = start ? v4l{} : paths.depth;
            paths.from = start ? v4l{} - 1 : paths.from;
            paths.into = start ? v4l{} : paths.into;
            paths.throughput = select(start, V3{splat(1), splat(1), splat(1)}, paths.throughput);
            paths.L = select(start, zero, paths.L);
            paths.full_emission |= start;
            paths.last_bsdf_pdf = select(start, v4d{}, paths.last_bsdf_pdf);
            paths.last_p = select(start, zero, paths.last_p);
            paths.last_sphere = start ? v4l{} - 1 : paths.last_sphere;
            paths.primary_distance = select(start, splat(kMissDepth), paths.primary_distance);
            if (sobol_lanes) {
                // The samplers' state moves into the lanes; the vertices below advance it there.
                for (int k = 0; k < 4; ++k) {
                    if (!start[k]) continue;
                    paths.sobol_key[k] = lane_sampler[k]->sobol_key();
                    paths.sobol_index[k] = lane_sampler[k]->index_reversed();
                    paths.sobol_dimension[k] = lane_sampler[k]->dimension();
                }
            }
        }
        if (!any_lane(paths.alive)) break;

        // Closest hits; a path whose ray leaves the scene ends.
        paths.rays -= paths.alive;
        v4d t;
        v4l id;
        closest_lanes(test_spheres, scene.spheres.size(), paths, t, id);
        paths.alive &= id >= 0;
        if (!any_lane(paths.alive)) continue;
        paths.primary_distance = select(paths.alive & (paths.depth == 0), t, paths.primary_distance);

        // Hit records (RenderScene::hit_at): the point projected back onto its sphere.
        const v4l hit_id = paths.alive ? id : v4l{};  // sphere 0 stands in for ended paths
        const SphereGeom* hit_sphere[4];
        for (int k = 0; k < 4; ++k) hit_sphere[k] = &scene.spheres[size_t(hit_id[k])];
        const V3 centre = gather(hit_sphere, &SphereGeom::centre);
        const v4d radius = gather(hit_sphere, &SphereGeom::radius);
        const V3 offset = (paths.o + paths.d * t) - centre;
        const v4d offset_length = sqrt_lanes(dot(offset, offset));
        const V3 n = select(offset_length > 0, offset * (1.0 / offset_length), -paths.d);
        const V3 p = centre + n * radius;

        // Emission seen along the path (rare: per lane, where a lane has hit a light).
        const v4l emits = paths.alive & ((((v4l{} + emitters) >> hit_id) & 1) != 0);
        if (any_lane(emits))
            for (int k = 0; k < 4; ++k) {
                if (!emits[k]) continue;
                const AreaLight& light = scene.area_lights[size_t(scene.sphere_light[size_t(id[k])])];
                const Hit hit{t[k], int(id[k]), lane(p, k), lane(n, k)};
                const PathHistory history{paths.full_emission[k] != 0, paths.last_bsdf_pdf[k], lane(paths.last_p, k),
                                          int(paths.last_sphere[k])};
                const double weight =
                    emission_weight(scene, settings.light_sampling, light, hit, lane(paths.d, k), history);
                const Color add = lane(paths.throughput, k) * light.radiance * weight;
                set_lane(paths.L, k, lane(paths.L, k) + add);
            }
        paths.alive &= paths.depth < settings.max_depth;
        if (!any_lane(paths.alive)) continue;

        const v4l front = dot(paths.d, n) < 0;
        const V3 ns = select(front, n, -n);

        // Each vertex's material and the numbers it reads (vertex_numbers_used, from the tables).
        const Material* lane_material[4] = {&scene.materials[0], &scene.materials[0], &scene.materials[0],
                                            &scene.materials[0]};
        unsigned use[4] = {}, use_any = 0;
        for (int k = 0; k < 4; ++k) {
            if (!paths.alive[k]) continue;
            lane_material[k] = sphere_material[size_t(id[k])];
            const bool roulette = paths.depth[k] + 1 >= settings.rr_depth;
            use[k] = sphere_use[size_t(id[k])] | (roulette ? Sampler::use_roulette : 0u);
            use_any |= use[k];
        }
        // has_smooth_lobe, lane-wise.
        const v4l diffuse = paths.alive & of_type(lane_material, MaterialType::diffuse);
        // The vertex's numbers, lane-wise: Sobol ones drawn in lanes (each lane reads those its
        // `use` names; the light choice is 0 where unread, as next_vertex gives), the others
        // drawn one lane at a time and gathered.
        using Numbers = Sampler::VertexNumbers;
        VertexLanes u;
        if (sobol_lanes) {
            u = sobol_vertex_lanes(paths.sobol_key, paths.sobol_index, paths.sobol_dimension,
                                   use_any & Sampler::use_lobe);
            paths.sobol_dimension += 5;
            const v4l pick_read = v4l{-int64_t((use[0] & Sampler::use_light_pick) != 0),
                                      -int64_t((use[1] & Sampler::use_light_pick) != 0),
                                      -int64_t((use[2] & Sampler::use_light_pick) != 0),
                                      -int64_t((use[3] & Sampler::use_light_pick) != 0)};
            u.light_pick = select(pick_read, u.light_pick, v4d{});
        } else {
            Numbers numbers[4];  // 0 for those a vertex does not read, as next_vertex gives
            for (int k = 0; k < 4; ++k)
                if (paths.alive[k]) numbers[k] = lane_sampler[k]->next_vertex(use[k]);
            u = {gather(numbers, &Numbers::light_pick), gather_x(numbers, &Numbers::light),
                 gather_y(numbers, &Numbers::light),    gather(numbers, &Numbers::lobe),
                 gather_x(numbers, &Numbers::bsdf),     gather_y(numbers, &Numbers::bsdf),
                 gather(numbers, &Numbers::roulette)};
        }

        // Diffuse vertices whose chosen light is an area light seen from outside (not the hit
        // sphere, the point outside it) sample it lane-wise, below.
        v4l light_lane{}, light_to{};
        v4d light_select{}, light_radius{};
        V3 light_centre{};
        const AreaLight* area[4];
        const SphereGeom* geom[4];
        if (lane_lights && !scene.area_lights.empty() && any_lane(diffuse)) {
            const v4l area_index = diffuse ? area_choice_lanes(scene, u.light_pick) : v4l{} - 1;
            for (int k = 0; k < 4; ++k) {
                area[k] = &scene.area_lights[area_index[k] >= 0 ? size_t(area_index[k]) : 0];
                geom[k] = &scene.spheres[size_t(area[k]->sphere)];
            }
            light_select = gather(area, &AreaLight::select_prob);
            light_to = gather(area, &AreaLight::sphere);
            light_centre = gather(geom, &SphereGeom::centre);
            light_radius = gather(geom, &SphereGeom::radius);
            const V3 from_light = p - light_centre;
            light_lane = (area_index >= 0) & (light_select > 0) & (light_to != id) &
                         (dot(from_light, from_light) > light_radius * light_radius);
        }

        // Per lane, through the functions one path uses: the samples of other lights (point
        // lights, lights around the vertex, the `area` and `brief-area` strategies) at diffuse
        // vertices. Written to plain records and gathered into lanes after the loop: stores
        // into single lanes of a vector would stall its next load.
        const v4l per_lane = next_event_possible ? diffuse & ~light_lane : v4l{};
        v4l shadow_cast{}, shadow_into{}, shadow_to{};
        V3 shadow_d = ns, direct{};
        v4d shadow_tmax{};
        if (any_lane(per_lane)) {
            LaneVertex vertex[4] = {};
            for (int k = 0; k < 4; ++k) {
                if (!per_lane[k]) continue;
                Numbers lane_u;  // the lane's record, 0 for the numbers it does not read
                if (use[k] & Sampler::use_light_pick) lane_u.light_pick = u.light_pick[k];
                if (use[k] & Sampler::use_light) lane_u.light = {u.light_x[k], u.light_y[k]};
                const Hit hit{t[k], int(id[k]), lane(p, k), lane(n, k)};
                const SurfacePoint sp{hit.n, front[k] != 0};
                Ray shadow;
                Color light;
                LaneVertex& v = vertex[k];
                if (sample_one_light(scene, settings, *lane_material[k], hit, sp, lane_u.light_pick, lane_u.light,
                                     shadow, light)) {
                    v.shadow = true;
                    v.shadow_d = shadow.d;
                    v.shadow_tmax = shadow.tmax;
                    v.shadow_into = shadow.into_from_sphere ? -1 : 0;
                    v.shadow_to = shadow.to_sphere;
                    v.direct = lane(paths.throughput, k) * light;
                }
            }
            shadow_cast = gather_mask(vertex, &LaneVertex::shadow);
            shadow_d = select(shadow_cast, gather(vertex, &LaneVertex::shadow_d), ns);
            shadow_tmax = gather(vertex, &LaneVertex::shadow_tmax);
            shadow_into = gather(vertex, &LaneVertex::shadow_into), shadow_to = gather(vertex, &LaneVertex::shadow_to);
            direct = gather(vertex, &LaneVertex::direct);
        }
        const V3 rho = gather(lane_material, &Material::rho);
        const V3 shadow_o = p;
        const v4l shadow_from = id;

        // area_light_direct (integrator.cpp) for those lanes: the light sample, the diffuse lobe
        // towards it (eval_smooth, pdf_smooth) and the power heuristic.
        if (any_lane(light_lane)) {
            const V3 light_radiance = gather(area, &AreaLight::radiance);
            const LightLanes ls = sample_light_lanes(settings.light_sampling, light_centre, light_radius, p, u.light_x,
                                                     u.light_y, light_lane);
            const v4d cos_o = dot(ns, ls.wi);
            const v4d lambert = select(cos_o > 0, kInvPi * cos_o, v4d{});
            const V3 f_cos = rho * lambert;
            const v4l lit = ls.valid & ~((f_cos.x == 0) & (f_cos.y == 0) & (f_cos.z == 0));
            const v4d p_light = light_select * ls.mis_pdf, p_bsdf = select(cos_o > 0, cos_o * kInvPi, v4d{});
            const v4d weight_mis = select(ls.mis_pdf > 0, p_light * p_light / (p_light * p_light + p_bsdf * p_bsdf),
                                          splat(1.0));
            const V3 light = (f_cos * light_radiance) * (weight_mis / (light_select * ls.pdf));
            shadow_cast |= lit;
            shadow_d = select(lit, ls.wi, shadow_d);
            shadow_tmax = select(lit, ls.distance, shadow_tmax);
            shadow_into = lit ? v4l(dot(ls.wi, n) < 0) : shadow_into;
            shadow_to = lit ? light_to : shadow_to;
            direct = select(lit, paths.throughput * light, direct);
        }

        // The light samples' shadow rays, together; each clear one adds its light.
        if (any_lane(shadow_cast)) {
            paths.rays -= shadow_cast;
            const v4l clear = shadow_cast & ~occluded_lanes(test_spheres, scene.spheres.size(), shadow_o, shadow_d,
                                                            shadow_from, shadow_into, shadow_tmax, shadow_to,
                                                            shadow_cast);
            paths.L = select(clear, paths.L + direct, paths.L);
        }

        // The next direction: the diffuse bounce (sample_material's diffuse case) and the other
        // materials' scattering, lane-wise.
        V3 next_dir{}, weight{};
        v4d pdf{};
        v4l ok{};
        const v4l other = paths.alive & ~diffuse;
        if (any_lane(other)) {
            const ScatterLanes scatter =
                scatter_lanes(lane_material, rho, other, paths.d, ns, front,
                              u.lobe, u.bsdf_x, u.bsdf_y);
            next_dir = scatter.direction;
            weight = scatter.weight;
            ok = other & scatter.ok;
        }
        if (any_lane(diffuse)) {
            const V3 local = cosine_hemisphere_lanes(u.bsdf_x, u.bsdf_y);
            const v4d cos_pdf = select(local.z > 0, local.z * kInvPi, v4d{});
            next_dir = select(diffuse, to_world_lanes(ns, local), next_dir);
            weight = select(diffuse, rho, weight);
            pdf = select(diffuse, cos_pdf, pdf);
            ok = diffuse ? v4l(cos_pdf > 0) : ok;
        }
        const v4l smooth = diffuse;
        paths.alive &= ok;
        paths.throughput = select(paths.alive, paths.throughput * weight, V3{v4d{}, v4d{}, v4d{}});
        paths.full_emission = naive ? ~v4l{} : ~smooth;
        paths.last_bsdf_pdf = pdf;
        paths.last_p = p;
        paths.last_sphere = id;
        paths.o = p;
        paths.d = next_dir;
        paths.from = id;
        paths.into = dot(next_dir, n) < 0;

        // Russian roulette with q = max(throughput) (brief), past the threshold depth.
        const v4l roulette = paths.alive & (paths.depth + 1 >= settings.rr_depth);
        if (any_lane(roulette)) {
            const V3& th = paths.throughput;
            const v4d y_or_z = select(th.y < th.z, th.z, th.y);
            const v4d largest = select(th.x < y_or_z, y_or_z, th.x);
            const v4d q = select(largest < 1.0, largest, splat(1.0));
            paths.alive &= ~roulette | (u.roulette < q);
            paths.throughput = select(paths.alive, select(roulette, paths.throughput * (1.0 / q), paths.throughput),
                                      V3{v4d{}, v4d{}, v4d{}});
        }
        paths.depth += 1;
    }
}

KR_CLONES void camera_rays(const RenderScene& scene, int width, int height, const int* xs, const int* ys,
                           Sampler* const* samplers, int count, Ray* rays) {
    const CameraModel& camera = scene.camera;
    for (int first = 0; first < count; first += 4) {
        const int n = std::min(4, count - first);
        bool lanes = camera.lens_radius <= 0;
        for (int k = first; k < first + n; ++k) lanes &= samplers[k]->sobol() && samplers[k]->dimension() == 0;
        if (!lanes) {
            for (int k = first; k < first + n; ++k) {
                Sampler& sampler = *samplers[k];
                const Vec2 sub = sampler.pixel();
                Vec2 lens;
                if (camera.lens_radius > 0) lens = sampler.next_2d();
                else sampler.skip_2d();  // a pinhole's image stays the same as a tiny lens's
                const Vec2 film = raster_to_camera(xs[k] + sub.x, ys[k] + sub.y, width, height);
                const CameraRay cr = camera.generate(film.x, film.y, lens.x, lens.y);
                rays[k] = Ray();
                rays[k].o = cr.origin;
                rays[k].d = cr.direction;
            }
            continue;
        }
        // Sampler::pixel (Sobol dimension 0) and the lens's skip, lane-wise; lanes past `n`
        // repeat the first sample.
        v4w key, index_reversed;
        v4d x, y;
        for (int k = 0; k < 4; ++k) {
            const int i = first + (k < n ? k : 0);
            key[k] = samplers[i]->sobol_key();
            index_reversed[k] = samplers[i]->index_reversed();
            x[k] = xs[i], y[k] = ys[i];
        }
        for (int k = first; k < first + n; ++k) samplers[k]->skip_dimensions(2);
        const SobolDimension<v4w> pixel(key, index_reversed, v4w{});
        // raster_to_camera, then CameraModel::generate for a pinhole: the point on the image
        // plane at distance 1, normalised.
        const v4d fx = ((x + unit_lanes(pixel.x())) - 0.5) / double(width);
        const v4d fy = ((y + unit_lanes(pixel.y())) + 0.5) / double(height);
        const v4d px = (2.0 * fx - 1.0) * camera.tan_half_fov * camera.aspect;
        const v4d py = (1.0 - 2.0 * fy) * camera.tan_half_fov;
        const V3 dir{camera.forward.x + px * camera.right.x + py * camera.up.x,
                     camera.forward.y + px * camera.right.y + py * camera.up.y,
                     camera.forward.z + px * camera.right.z + py * camera.up.z};
        const V3 unit = dir * (1.0 / sqrt_lanes(dot(dir, dir)));
        for (int k = 0; k < n; ++k) {
            Ray& ray = rays[first + k];
            ray = Ray();
            ray.o = camera.position;
            ray.d = lane(unit, k);
        }
    }
}

void trace_samples(const RenderScene& scene, const RenderSettings& settings, const Ray* rays, Sampler* const* samplers,
                   int count, SampleResult* results) {
    bool camera_rays = true;  // as trace_packet takes them
    for (int k = 0; k < count; ++k)
        camera_rays &=
            rays[k].tmin == 0 && rays[k].tmax == kInf && rays[k].from_sphere < 0 && rays[k].to_sphere < 0;
    if (packets_apply(scene, settings) && camera_rays && count > 1) {
        trace_packet(scene, settings, rays, samplers, count, results);
    } else {
        for (int k = 0; k < count; ++k) results[k] = trace_sample(scene, settings, rays[k], *samplers[k]);
    }
}

}  // namespace kr
