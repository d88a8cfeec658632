// The lane-wise path tracer's kernels (lanes.cpp has what they do), compiled once per SIMD
// target (targets.h): CMake defines KR_LANE_TARGET (the target's id, this file's namespace),
// KR_LANE_TARGET_<id> (math.h's lane type for it) and its CPU level (levels.h), whose
// instructions everything between KR_LEVEL_BEGIN and KR_LEVEL_END below is compiled for. The
// lanes' parts are in headers by concept: math.h (types and sampling maths), sobol.h (Sobol
// numbers), tables.h (gathers and per-sphere columns) and cast.h (ray casting); the physics
// of a path vertex, which the kernels share with one path, is vertex.h's (vertex.inc,
// compiled here again for the target's lanes). What is here: the path loop and its
// plumbing.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "core/sampling.h"
#include "render/accel.h"
#include "render/lanes/lanes.h"
#include "render/lanes/levels.h"
#include "render/lanes/pixel_sums.h"
#include "render/lanes/targets.h"
#include "render/path.h"
#include "render/precision.h"
#include "render/trace.h"

// Where this build cannot compile the target (CMakeLists.txt: Clang on a machine without its
// level, or a GCC sanitizer build), the target is not built: its entry points are null.
#ifdef KR_LANE_TARGET_OFF
namespace kr::lanes::KR_LANE_TARGET {
const TargetKernels kernels{};
}  // namespace kr::lanes::KR_LANE_TARGET
#else

KR_LEVEL_BEGIN
namespace kr::lanes::KR_LANE_TARGET {

namespace {

#include "render/lanes/math.h"
#include "render/lanes/sobol.h"
#include "render/lanes/tables.h"
#include "render/lanes/cast.h"


// vertex.h's physics, compiled for this build's instruction set and lanes.
namespace vertex {
#include "render/lanes/vertex.inc"
}  // namespace vertex

// What a path vertex's per-lane part (the light samples taken one lane at a time) hands to the
// lane-wise part. All zeros for a lane with nothing to do: the lane-wise part masks what such a
// lane computes (zeros, as one block of stores, cost a fifth of what member defaults did).
struct LaneVertex {
    bool shadow;
    Vec3 shadow_d, direct;
    double shadow_tmax;
    int64_t shadow_into, shadow_to;
};

// The lanes' paths.
struct Paths {
    V3 o, d;  // the rays to cast next: from a surface or the camera, tmin 0, unbounded
    vm from, into;
    vm alive;
    vm depth;  // of the vertex the next ray finds
    V3 throughput, L;
    vf medium_eta, radiance_scale;  // MediumScale (material.h), lane-wise
    vm full_emission;  // PathHistory, lane-wise
    vf last_bsdf_pdf;
    V3 last_p;
    vm last_sphere;
    vf primary_distance;
    vw sobol_key, sobol_index, sobol_dimension;  // Sobol samplers' state (sobol_lanes)
    vm rays;  // cast so far per path (masks are -1 where set, so subtracting one counts it)
};

// Where the lanes' paths start: the batch's camera rays, as Ray records (any camera; they start
// at tmin 0, unbounded, from no sphere: trace_samples checks), for samplers of any estimator.
// A source's `start` puts the camera rays of the lanes in `start` into `o` and `d`: lane k
// takes sample `sample[k]`; the started lanes' samples are `first`, first + 1, ... in lane
// order.
struct RayRecords {
    const Ray* rays;
    static constexpr bool kSobolOnly = false;
    KR_LANES void start(vm start, const int (&sample)[kLanes], int, V3& o, V3& d) const {
        o = select(start, lanes_of_vec3([&](size_t k) -> const Vec3& { return rays[sample[k]].o; }), o);
        d = select(start, lanes_of_vec3([&](size_t k) -> const Vec3& { return rays[sample[k]].d; }), d);
    }
};

#ifdef KR_LANES_FLOAT
// The same for camera rays the lanes made themselves (trace_camera_lanes), as columns the
// lanes gather by sample (padded to whole vectors): the samples' unit directions, and their
// origins on a thin lens (a pinhole's are its position); and their Sobol samplers' keys and
// reversed indices, the samplers being at dimension 2 (after the pixel and the lens): no
// Sampler is read. kLens: a thin lens's origins, else the pinhole's position.
template <bool kLens>
struct CameraColumns {
    Vec3 position;
    const float *x, *y, *z, *ox, *oy, *oz;
    const uint32_t *key, *index_reversed;
    static constexpr bool kSobolOnly = true;
#ifdef KR_LANES_V4
    // The started lanes' samples are consecutive: one expanding load per column (vexpandps)
    // puts them into their lanes, where a gather loads every lane one by one.
    KR_LANES static void start_columns(const float* x, const float* y, const float* z, vm start, int first, V3& v) {
        __m512i bits;
        __builtin_memcpy(&bits, &start, sizeof bits);
        const __mmask16 lanes = _mm512_test_epi32_mask(bits, bits);
        v = {_mm512_mask_expandloadu_ps(v.x, lanes, x + first), _mm512_mask_expandloadu_ps(v.y, lanes, y + first),
             _mm512_mask_expandloadu_ps(v.z, lanes, z + first)};
    }
    KR_LANES void start(vm start, const int (&)[kLanes], int first, V3& o, V3& d) const {
        if constexpr (kLens) start_columns(ox, oy, oz, start, first, o);
        else o = select(start, V3{splat(position.x), splat(position.y), splat(position.z)}, o);
        start_columns(x, y, z, start, first, d);
    }
    KR_LANES static vw start_words(const uint32_t* column, vm start, int first, vw v) {
        __m512i bits, words;
        __builtin_memcpy(&bits, &start, sizeof bits);
        __builtin_memcpy(&words, &v, sizeof words);
        words = _mm512_mask_expandloadu_epi32(words, _mm512_test_epi32_mask(bits, bits), column + first);
        __builtin_memcpy(&v, &words, sizeof v);
        return v;
    }
    KR_LANES void start_sobol(vm start, const int (&)[kLanes], int first, vw& sobol_key, vw& sobol_index,
                              vw& sobol_dimension) const {
        sobol_key = start_words(key, start, first, sobol_key);
        sobol_index = start_words(index_reversed, start, first, sobol_index);
        sobol_dimension = start ? vw{} + 2 : sobol_dimension;  // past the pixel and the lens
    }
#else
    KR_LANES static V3 gather_columns(const float* x, const float* y, const float* z, const int (&sample)[kLanes]) {
        __m256i index;
        __builtin_memcpy(&index, sample, sizeof index);
        return {_mm256_i32gather_ps(x, index, 4), _mm256_i32gather_ps(y, index, 4), _mm256_i32gather_ps(z, index, 4)};
    }
    KR_LANES void start(vm start, const int (&sample)[kLanes], int, V3& o, V3& d) const {
        if constexpr (kLens) o = select(start, gather_columns(ox, oy, oz, sample), o);
        else o = select(start, V3{splat(position.x), splat(position.y), splat(position.z)}, o);
        d = select(start, gather_columns(x, y, z, sample), d);
    }
    KR_LANES static vw gather_words(const uint32_t* column, vm start, const int (&sample)[kLanes], vw v) {
        __m256i index, words;
        __builtin_memcpy(&index, sample, sizeof index);
        words = _mm256_i32gather_epi32(reinterpret_cast<const int*>(column), index, 4);
        vw gathered;
        __builtin_memcpy(&gathered, &words, sizeof gathered);
        return start ? gathered : v;
    }
    KR_LANES void start_sobol(vm start, const int (&sample)[kLanes], int, vw& sobol_key, vw& sobol_index,
                              vw& sobol_dimension) const {
        sobol_key = gather_words(key, start, sample, sobol_key);
        sobol_index = gather_words(index_reversed, start, sample, sobol_index);
        sobol_dimension = start ? vw{} + 2 : sobol_dimension;  // past the pixel and the lens
    }
#endif
};
#endif

// Sphere s's light's row in the lanes' light table (which holds the lights on spheres), or -1.
int light_row(const RenderScene& scene, size_t s) {
    return scene.sphere_light[s] >= 0 ? scene.sphere_light[s] - int(scene.lights_off_spheres) : -1;
}

// The per-sphere and per-light tables of a batch and where its rays are cast: fixed columns
// and the one leaf's spheres in turn for scenes of up to 16 spheres, columns in a buffer
// (WideStore) and the lane tree for larger ones.
template <bool kWide>
struct LaneScene;
template <>
struct LaneScene<false> {
    SphereTable<false> table{};
    LightTable<false> lights{};
    TestSphere test_spheres[kMaxLeafSpheres];
    size_t count;
    lane_int emitters = 0;  // a bit per sphere: whether it carries a light
    IndexColumnOf<false> light{};  // per sphere, its light's row in `lights`, or -1
    // The lanes whose hit sphere carries a light.
    KR_LANES vm emits(vm hit_id) const { return (((vm{} + emitters) >> hit_id) & 1) != 0; }
    KR_LANES void closest(const V3& o, const V3& d, vm from, vm into, vm alive, vf& best, vm& best_id) const {
        closest_lanes(test_spheres, count, o, d, from, into, alive, best, best_id);
    }
    KR_LANES vm occluded(const V3& o, const V3& d, vm from, vm into, vf tmax, vm to, vm cast) const {
        return occluded_lanes(test_spheres, count, o, d, from, into, tmax, to, cast);
    }
    explicit LaneScene(const RenderScene& scene) : count(scene.spheres.size()) {
        for (size_t s = 0; s < scene.spheres.size(); ++s) {
            const SphereGeom& geom = scene.spheres[s];
            test_spheres[s] = {real(geom.centre.x), real(geom.centre.y), real(geom.centre.z),
                               real(geom.radius * geom.radius),
                               real(std::abs(geom.centre.x) + std::abs(geom.centre.y) + std::abs(geom.centre.z)),
                               int32_t(s)};
            if (scene.sphere_light[s] >= 0) emitters |= lane_int(1) << s;
            light.v[s] = lane_int(light_row(scene, s));
        }
    }
};
template <>
struct LaneScene<true> {
    WideStore store;
    SphereTable<true> table;
    LightTable<true> lights;
    IndexColumnOf<true> light;  // per sphere, its light's row in `lights`, or -1
    const LaneNode* nodes;
    const TestSphere* spheres;
    // Up to kLaneScanMaxSpheres the float lanes test every sphere, a cluster at a time
    // (closest_clusters: the same hits), rather than walk the tree. None: the tree.
    const LaneCluster* clusters = nullptr;
    size_t cluster_count = 0;
    const TestSphere* scan = nullptr;
    KR_LANES void closest(const V3& o, const V3& d, vm from, vm into, vm alive, vf& best, vm& best_id) const {
        if (clusters) return closest_clusters(clusters, cluster_count, scan, o, d, from, into, alive, best, best_id);
        closest_tree(nodes, spheres, o, d, from, into, alive, best, best_id);
    }
    KR_LANES vm emits(vm hit_id) const { return look_up(light, hit_id) >= 0; }
    KR_LANES vm occluded(const V3& o, const V3& d, vm from, vm into, vf tmax, vm to, vm cast) const {
        if (clusters) return occluded_clusters(clusters, cluster_count, scan, o, d, from, into, tmax, to, cast);
        return occluded_tree(nodes, spheres, o, d, from, into, tmax, to, cast);
    }
    explicit LaneScene(const RenderScene& scene)
        : store(std::max(scene.spheres.size(), size_t(1)), SphereTable<true>::kReals + LightTable<true>::kReals,
                SphereTable<true>::kInts + LightTable<true>::kInts + 1) {
        table.bind(store);
        lights.bind(store);
        store.bind(light);
        for (size_t s = 0; s < scene.spheres.size(); ++s) light.data()[s] = lane_int(light_row(scene, s));
        const LaneTree& tree = scene.bvh.lane_tree();
        nodes = tree.nodes.data();
#ifdef KR_LANES_FLOAT
        spheres = tree.spheres_f.data();
#else
        spheres = tree.spheres_d.data();
#endif
#ifdef KR_LANES_FLOAT
        if (!tree.clusters.empty())
            clusters = tree.clusters.data(), cluster_count = tree.clusters.size(), scan = tree.scan_f.data();
#endif
    }
};

// ---- The path loop's stages ----
// trace_paths below runs them in this order, a bounce of every lane's path at a time. Each is
// forced inline and keeps the blocks it would have in one function: GCC fuses a product into a
// sum only within one basic block, so a stage's bounds must not move a product away from its
// sum. Where GCC's block layout still decides (the emission's masked sum in the sixteen
// lanes), the sum is fused explicitly (mul_add_lanes), so the images keep their bits.

// Which sample each lane traces, and where the samples come from.
struct LaneSamples {
    int sample[kLanes];               // the sample each lane traces, -1: none
    Sampler* sampler[kLanes] = {};    // its sampler (not for CameraColumns' Sobol columns)
    int next = 0;                     // the next sample to start
    bool sobol_lanes = true;          // Sobol samplers: their vertex numbers are drawn lane-wise
};

// 1. Lanes whose path has ended hand in its result and start the next sample's. The new
// paths' state is blended in lane-wise: stores into single lanes would stall the vectors' next
// loads. (A loop over the ended lanes' bits: testing the alive mask lane by lane is dearer,
// docs/performance.md, "Design choices and their figures".)
template <class Source>
KR_LANES void start_samples(const Source& source, Sampler* const* samplers, int count, SampleResult* results,
                            LaneSamples& lanes, Paths& paths) {
    vm start{};
    int start_sample[kLanes] = {};
    const int first_started = lanes.next;
    for (unsigned ended = ~lane_bits(paths.alive) & ((1u << kLanes) - 1); ended != 0; ended &= ended - 1) {
        const int k = __builtin_ctz(ended);
        if (lanes.sample[k] >= 0) {
            SampleResult& r = results[lanes.sample[k]];
            r.radiance = lane(paths.L, k);
            r.primary_distance = paths.primary_distance[k];
            r.rays = uint64_t(paths.rays[k]);
            lanes.sample[k] = -1;
        }
        if (lanes.next == count) continue;
        lanes.sample[k] = lanes.next;
        if constexpr (!Source::kSobolOnly) lanes.sampler[k] = samplers[lanes.next];
        start_sample[k] = lanes.next;
        start[k] = -1;
        ++lanes.next;
    }
    if (!any_lane(start)) return;
    const V3 zero{vf{}, vf{}, vf{}};
    source.start(start, start_sample, first_started, paths.o, paths.d);
    paths.alive |= start;
    paths.rays = start ? vm{} : paths.rays;
    paths.depth = start ? vm{} : paths.depth;
    paths.from = start ? vm{} - 1 : paths.from;
    paths.into = start ? vm{} : paths.into;
    paths.throughput = select(start, V3{splat(1), splat(1), splat(1)}, paths.throughput);
    paths.medium_eta = select(start, splat(1), paths.medium_eta);
    paths.radiance_scale = select(start, splat(1), paths.radiance_scale);
    paths.L = select(start, zero, paths.L);
    paths.full_emission |= start;
    paths.last_bsdf_pdf = select(start, vf{}, paths.last_bsdf_pdf);
    paths.last_p = select(start, zero, paths.last_p);
    paths.last_sphere = start ? vm{} - 1 : paths.last_sphere;
    paths.primary_distance = select(start, splat(kMissDepth), paths.primary_distance);
    if constexpr (Source::kSobolOnly) {
        // The samplers' state, from the source's columns, into the lanes; the vertices below
        // advance it there.
        source.start_sobol(start, start_sample, first_started, paths.sobol_key, paths.sobol_index,
                           paths.sobol_dimension);
    } else if (lanes.sobol_lanes) {
        // The same from the samplers.
        for (unsigned started = lane_bits(start); started != 0; started &= started - 1) {
            const int k = __builtin_ctz(started);
            paths.sobol_key[k] = lanes.sampler[k]->sobol_key();
            paths.sobol_index[k] = lanes.sampler[k]->index_reversed();
            paths.sobol_dimension[k] = lanes.sampler[k]->dimension();
        }
    }
}

// Where each lane's ray hit: the hit records (as fill_hit in render_scene.cpp).
struct HitLanes {
    vf t;
    vm id, hit_id;  // the sphere hit; hit_id: sphere 0 standing in for ended paths
    V3 centre;
    vf radius;
    V3 n, p;        // the outward normal, and the point projected back onto its sphere
};

// 2. The closest hits (a path whose ray leaves the scene ends) and their records. False: no
// path goes on.
template <bool kWide>
KR_LANES bool find_hits(const LaneScene<kWide>& lane_scene, Paths& paths, HitLanes& h) {
    paths.rays -= paths.alive;
    vf t;
    vm id;  // (locals: the sphere loop keeps them in registers, where h's would be stored)
    lane_scene.closest(paths.o, paths.d, paths.from, paths.into, paths.alive, t, id);
    h.t = t, h.id = id;
    paths.alive &= h.id >= 0;
    if (!any_lane(paths.alive)) return false;
    paths.primary_distance = select(paths.alive & (paths.depth == 0), h.t, paths.primary_distance);
    h.hit_id = paths.alive ? h.id : vm{};
    h.centre = look_up(lane_scene.table.centre, h.hit_id);
    h.radius = look_up(lane_scene.table.radius, h.hit_id);
    const V3 offset = (paths.o + paths.d * h.t) - h.centre;
    const vf offset_length = sqrt_lanes(dot(offset, offset));
    h.n = select(offset_length > 0, offset * (1.0 / offset_length), -paths.d);
    h.p = h.centre + h.n * h.radius;
    return true;
}

// 3. Emission seen along the path: weighed against the last vertex's light sample where that
// could have found it (vertex.h's emission_mis_weight), else counted whole.
template <bool kWide>
KR_LANES void add_emission(const LaneScene<kWide>& lane_scene, LightSampling sampling, const HitLanes& h,
                           Paths& paths) {
    const vm emits = paths.alive & lane_scene.emits(h.hit_id);
    if (any_lane(emits)) {
        const vm light = emits ? look_up(lane_scene.light, h.hit_id) : vm{};
        const vm weighed = emits & ~paths.full_emission & (paths.last_sphere != h.id);
        vf weight = splat(1.0);
        if (any_lane(weighed))
            weight = select(weighed,
                            vertex::emission_mis_weight<Lanes>(sampling, h.centre, h.radius,
                                                               look_up(lane_scene.lights.select_prob, light),
                                                               paths.last_p, paths.d, h.t, h.n, paths.last_bsdf_pdf,
                                                               weighed),
                            weight);
        // L + seen, seen = (throughput * scale * radiance) * weight, as one fused sum.
        const V3 radiance = (paths.throughput * paths.radiance_scale) * look_up(lane_scene.lights.radiance, light);
        paths.L = select(emits, mul_add_lanes(radiance, weight, paths.L), paths.L);
    }
}

// 4. Each vertex's numbers, lane-wise: Sobol ones drawn in lanes (each lane reads those its
// `use` names; the light choice is 0 where unread, as next_vertex gives), the others drawn one
// lane at a time and gathered.
KR_LANES VertexLanes draw_numbers(const LaneSamples& lanes, vm use, unsigned use_any, Paths& paths) {
    using Numbers = Sampler::VertexNumbers;
    VertexLanes u;
    if (lanes.sobol_lanes) {
        u = sobol_vertex_lanes(paths.sobol_key, paths.sobol_index, paths.sobol_dimension, use_any);
        paths.sobol_dimension += 5;
        u.light_pick = select((use & lane_int(Sampler::use_light_pick)) != 0, u.light_pick, vf{});
    } else {
        Numbers numbers[kLanes];  // 0 for those a vertex does not read, as next_vertex gives
        for (int k = 0; k < kLanes; ++k)
            if (paths.alive[k]) numbers[k] = lanes.sampler[k]->next_vertex(unsigned(use[k]));
        u = {gather(numbers, &Numbers::light_pick), gather_x(numbers, &Numbers::light),
             gather_y(numbers, &Numbers::light),    gather(numbers, &Numbers::lobe),
             gather_x(numbers, &Numbers::bsdf),     gather_y(numbers, &Numbers::bsdf),
             gather(numbers, &Numbers::roulette)};
    }
    return u;
}

// A light on a sphere that lanes sample lane-wise (step 5).
struct SphereLightLanes {
    vm lane{}, to{};     // the lanes that sample it; its sphere
    vm index{};          // its row in the lanes' light table (lane), else 0
    vf select{}, radius{};
    V3 centre{};
};

// 5. Diffuse vertices whose chosen light is on a sphere seen from outside (not the hit sphere,
// the point outside it) sample it lane-wise (step 7).
template <bool kWide>
KR_LANES SphereLightLanes choose_sphere_lights(const RenderScene& scene, const LaneScene<kWide>& lane_scene,
                                               const HitLanes& h, vm smooth, vf light_pick) {
    SphereLightLanes c;
    // The chosen light's row in `lights` (negative: none, or a light off the spheres).
    const vm area_index = smooth ? vertex::choose_light<Lanes>(scene, false, light_pick) -
                                       lane_int(scene.lights_off_spheres)
                                 : vm{} - 1;
    c.index = (area_index >= 0) & area_index;
    c.select = look_up(lane_scene.lights.select_prob, c.index);
    c.to = look_up(lane_scene.lights.sphere, c.index);
    c.centre = look_up(lane_scene.lights.centre, c.index);
    c.radius = look_up(lane_scene.lights.radius, c.index);
    const V3 from_light = h.p - c.centre;
    c.lane = (area_index >= 0) & (c.select > 0) & (c.to != h.id) & (dot(from_light, from_light) > c.radius * c.radius);
    return c;
}

// The vertices' shadow rays (from the hit points) and the light each brings if it is clear.
struct ShadowLanes {
    vm cast{}, into{}, to{};
    V3 d, direct{};
    vf tmax{};
};

// 6. Per lane, through the functions one path uses: the samples of other lights (lights off
// the spheres, lights around the vertex, the `area` and `brief-area` strategies) at diffuse
// vertices. Written to plain records and gathered into lanes after the loop: stores into
// single lanes of a vector would stall its next load.
KR_LANES void sample_lights_per_lane(const RenderScene& scene, const RenderSettings& settings, const HitLanes& h,
                                     vm front, vm use, const VertexLanes& u, vm per_lane, const Paths& paths,
                                     ShadowLanes& shadow) {
    using Numbers = Sampler::VertexNumbers;
    // (The hit's lanes read by index from copies: an indexed read of h's own would keep all of
    // h in memory for the whole loop.)
    const vf t = h.t;
    const vm id = h.id;
    const V3 p = h.p, n = h.n;
    LaneVertex vertex[kLanes] = {};
    for (unsigned left = lane_bits(per_lane); left != 0; left &= left - 1) {
        const int k = __builtin_ctz(left);
        Numbers lane_u;  // the lane's record, 0 for the numbers it does not read
        if (use[k] & Sampler::use_light_pick) lane_u.light_pick = u.light_pick[k];
        if (use[k] & Sampler::use_light) lane_u.light = {u.light_x[k], u.light_y[k]};
        const Hit hit{t[k], int(id[k]), lane(p, k), lane(n, k)};
        const SurfacePoint sp{hit.n, front[k] != 0};
        Ray ray;
        Color light;
        LaneVertex& v = vertex[k];
        const Material& material = scene.materials[size_t(scene.sphere_material[size_t(id[k])])];
        if (sample_one_light(scene, settings, material, hit, sp, lane_u.light_pick, lane_u.light, ray, light)) {
            v.shadow = true;
            v.shadow_d = ray.d;
            v.shadow_tmax = ray.tmax;
            v.shadow_into = ray.into_from_sphere ? -1 : 0;
            v.shadow_to = ray.to_sphere;
            v.direct = lane(paths.throughput, k) * double(paths.radiance_scale[k]) * light;
        }
    }
    shadow.cast = gather_mask(vertex, &LaneVertex::shadow);
    shadow.d = select(shadow.cast, gather(vertex, &LaneVertex::shadow_d), shadow.d);
    shadow.tmax = gather(vertex, &LaneVertex::shadow_tmax);
    shadow.into = gather(vertex, &LaneVertex::shadow_into), shadow.to = gather(vertex, &LaneVertex::shadow_to);
    shadow.direct = gather(vertex, &LaneVertex::direct);
}

// 7. light_direct (vertex.inc) for the lanes of step 5: the sphere light's sample, and what it
// brings (vertex.h).
template <class M>
KR_LANES void sample_sphere_lights(LightSampling sampling, const SphereLightLanes& c, const V3& light_radiance,
                                   const HitLanes& h, const VertexLanes& u, const M& m, const V3& ns,
                                   const Paths& paths, ShadowLanes& shadow) {
    const vertex::LightSample<Lanes> ls =
        vertex::sample_sphere_light<Lanes>(sampling, c.centre, c.radius, h.p, u.light_x, u.light_y, c.lane);
    const vertex::DirectLight<Lanes> light = vertex::direct_light<Lanes>(ls, m, ns, light_radiance, c.select, true);
    const vm lit = light.lit;
    shadow.cast |= lit;
    shadow.d = select(lit, ls.wi, shadow.d);
    shadow.tmax = select(lit, ls.distance, shadow.tmax);
    shadow.into = lit ? vm(dot(ls.wi, h.n) < 0) : shadow.into;
    shadow.to = lit ? c.to : shadow.to;
    shadow.direct = select(lit, (paths.throughput * paths.radiance_scale) * light.light, shadow.direct);
}

// 8. The light samples' shadow rays, together; each clear one adds its light.
template <bool kWide>
KR_LANES void cast_shadows(const LaneScene<kWide>& lane_scene, const HitLanes& h, const ShadowLanes& shadow,
                           Paths& paths) {
    paths.rays -= shadow.cast;
    const vm clear =
        shadow.cast & ~lane_scene.occluded(h.p, shadow.d, h.id, shadow.into, shadow.tmax, shadow.to, shadow.cast);
    paths.L = select(clear, paths.L + shadow.direct, paths.L);
}

// 9. The next direction (vertex.h's sample_material), then the path's state, and Russian
// roulette past the threshold depth.
template <class M>
KR_LANES void continue_paths(const RenderSettings& settings, bool naive, const M& m, const HitLanes& h, vm front,
                             const V3& ns, const VertexLanes& u, Paths& paths) {
    const vertex::Scatter<Lanes> scatter =
        vertex::sample_material<Lanes>(m, paths.alive, paths.d, ns, front, u.lobe, u.bsdf_x, u.bsdf_y);
    paths.alive &= scatter.ok;
    paths.throughput = select(paths.alive, paths.throughput * scatter.weight, V3{vf{}, vf{}, vf{}});
    const vm crossed = paths.alive & scatter.transmitted;
    if (any_lane(crossed))
        vertex::cross_medium<Lanes>(paths.medium_eta, paths.radiance_scale, crossed, front, scatter.eta);
    paths.full_emission = naive ? ~vm{} : ~scatter.smooth;
    paths.last_bsdf_pdf = scatter.pdf;
    paths.last_p = h.p;
    paths.last_sphere = h.id;
    paths.o = h.p;
    paths.d = scatter.direction;
    paths.from = h.id;
    paths.into = dot(scatter.direction, h.n) < 0;

    const vm roulette = paths.alive & (paths.depth + 1 >= settings.rr_depth);
    if (any_lane(roulette)) vertex::russian_roulette<Lanes>(paths.throughput, paths.alive, roulette, u.roulette);
    paths.depth += 1;
}

// `count` samples, a path per lane, a bounce at a time: a lane whose path ends hands in its
// result and takes the next sample, so lanes stay busy while paths have different lengths.
// `source` gives the samples' camera rays (RayRecords or CameraColumns).
template <bool kWide, class Source>
void trace_paths(const RenderScene& scene, const RenderSettings& settings, const Source& source,
                 Sampler* const* samplers, int count, SampleResult* results) {
    const bool naive = settings.integrator == Integrator::pt_naive;
    const bool next_event_possible = scene.light_count() > 0;
    // Lights on spheres sampled lane-wise: the `brief` and `cone` strategies (the others per lane).
    const bool lane_lights = !naive && (settings.light_sampling == LightSampling::brief ||
                                        settings.light_sampling == LightSampling::cone);
    Paths paths{};  // no lane alive: each path's state is set where its lane starts it, below
    LaneSamples lanes;
    std::fill(lanes.sample, lanes.sample + kLanes, -1);
    if constexpr (!Source::kSobolOnly)
        for (int k = 0; k < count; ++k) lanes.sobol_lanes &= samplers[k]->sobol();

    // Per sphere: its material and what a vertex on it reads, and its light. Per light on a
    // sphere: what its samples read. Where the rays are cast: the spheres or the tree.
    LaneScene<kWide> lane_scene(scene);
    auto& table = lane_scene.table;
    auto& lights = lane_scene.lights;
    // (Up to 16 materials on the stack: no allocation per batch for the brief's scenes.)
    unsigned few_used[kMaxLeafSpheres];
    std::vector<unsigned> many_used;
    unsigned* numbers_used = few_used;
    if (scene.materials.size() > kMaxLeafSpheres) {
        many_used.resize(scene.materials.size());
        numbers_used = many_used.data();
    }
    for (size_t i = 0; i < scene.materials.size(); ++i)
        numbers_used[i] = vertex_numbers_used(scene, scene.materials[i], 0, kMaxDepth + 2);
    for (size_t s = 0; s < scene.spheres.size(); ++s) {
        const SphereGeom& geom = scene.spheres[s];
        const size_t material_index = size_t(scene.sphere_material[s]);
        const Material& material = scene.materials[material_index];
        table.centre.set(s, geom.centre);
        table.radius.data()[s] = real(geom.radius);
        table.set_material(s, material);
        table.use.data()[s] = lane_int(numbers_used[material_index]);
    }
    for (size_t i = scene.lights_off_spheres; i < scene.lights.size(); ++i) {
        const RenderLight& light = scene.lights[i];
        const SphereGeom& geom = scene.spheres[size_t(light.sphere)];
        const size_t row = i - scene.lights_off_spheres;
        lights.centre.set(row, geom.centre);
        lights.radius.data()[row] = real(geom.radius);
        lights.radiance.set(row, light.power);
        lights.select_prob.data()[row] = real(light.select_prob);
        lights.sphere.data()[row] = lane_int(light.sphere);
    }
    for (;;) {
        start_samples(source, samplers, count, results, lanes, paths);
        if (!any_lane(paths.alive)) break;
        HitLanes h;
        if (!find_hits(lane_scene, paths, h)) continue;
        add_emission(lane_scene, settings.light_sampling, h, paths);
        paths.alive &= paths.depth < settings.max_depth;
        if (!any_lane(paths.alive)) continue;

        const vm front = dot(paths.d, h.n) < 0;
        const V3 ns = select(front, h.n, -h.n);
        // Each vertex's material and the numbers it reads (vertex_numbers_used, from the
        // tables; none in lanes that are not alive).
        const vm type = look_up(table.type, h.hit_id);
        const vm use = (look_up(table.use, h.hit_id) |
                        ((paths.depth + 1 >= settings.rr_depth) & lane_int(Sampler::use_roulette))) &
                       paths.alive;
        unsigned use_any = 0;
        for (int k = 0; k < kLanes; ++k) use_any |= unsigned(use[k]);
        const vm smooth =
            paths.alive & vertex::has_smooth_lobe<Lanes>(LaneMaterial<SphereTable<kWide>>{table, h.hit_id, type, {}});
        const VertexLanes u = draw_numbers(lanes, use, use_any, paths);

        SphereLightLanes sphere_lights;
        if (lane_lights && scene.lights_off_spheres < scene.lights.size() && any_lane(smooth))
            sphere_lights = choose_sphere_lights(scene, lane_scene, h, smooth, u.light_pick);
        const vm per_lane = next_event_possible ? smooth & ~sphere_lights.lane : vm{};
        ShadowLanes shadow;
        shadow.d = ns;
        if (any_lane(per_lane)) sample_lights_per_lane(scene, settings, h, front, use, u, per_lane, paths, shadow);
        const V3 rho = look_up_rho(table, h.hit_id);
        const LaneMaterial<SphereTable<kWide>> material{table, h.hit_id, type, rho};
        if (any_lane(sphere_lights.lane))
            sample_sphere_lights(settings.light_sampling, sphere_lights, look_up(lights.radiance, sphere_lights.index),
                                 h, u, material, ns, paths, shadow);
        if (any_lane(shadow.cast)) cast_shadows(lane_scene, h, shadow, paths);
        continue_paths(settings, naive, material, h, front, ns, u, paths);
    }
}

}  // namespace

// Whether the lanes' tables and ray casting take the wide form (LaneScene<true>).
bool wide_scene(const RenderScene& scene) { return !scene.bvh.one_leaf(); }

template <class Source>
void trace_paths_of(const RenderScene& scene, const RenderSettings& settings, const Source& source,
                    Sampler* const* samplers, int count, SampleResult* results) {
    if (wide_scene(scene)) trace_paths<true>(scene, settings, source, samplers, count, results);
    else trace_paths<false>(scene, settings, source, samplers, count, results);
}

void trace_lanes(const RenderScene& scene, const RenderSettings& settings, const Ray* rays, Sampler* const* samplers,
                  int count, SampleResult* results) {
    trace_paths_of(scene, settings, RayRecords{rays}, samplers, count, results);
}

// The closest sphere of each camera ray (-1: none), by the path loop's cast (find_hits), a
// vector of rays at a time; lanes past `count` repeat the first ray.
template <bool kWide>
void closest_spheres_of(const RenderScene& scene, const Ray* rays, int count, int* spheres) {
    const LaneScene<kWide> lane_scene(scene);
    for (int first = 0; first < count; first += kLanes) {
        const int n = std::min(kLanes, count - first);
        const auto ray = [&](size_t k) -> const Ray& { return rays[first + (int(k) < n ? int(k) : 0)]; };
        const V3 o = lanes_of_vec3([&](size_t k) -> const Vec3& { return ray(k).o; });
        const V3 d = lanes_of_vec3([&](size_t k) -> const Vec3& { return ray(k).d; });
        vf t;
        vm id;
        lane_scene.closest(o, d, vm{} - 1, vm{}, ~vm{}, t, id);
        for (int k = 0; k < n; ++k) spheres[first + k] = int(id[k]);
    }
}
void closest_spheres(const RenderScene& scene, const Ray* rays, int count, int* spheres) {
    (wide_scene(scene) ? closest_spheres_of<true> : closest_spheres_of<false>)(scene, rays, count, spheres);
}

// A camera ray per lane for Sobol samplers at their first dimension: camera_rays' steps
// (Sampler::pixel and the lens numbers, raster_to_camera, CameraModel::generate) lane-wise.
KR_LANES void camera_lanes(const CameraModel& camera, bool lens, int width, int height, vw key, vw index_reversed, vf x, vf y,
                           V3& origin, V3& direction) {
    with_lane_bit_reverse([&](auto reverse) KR_LANES_LAMBDA {
        using Sobol = LaneSobol<vw, decltype(reverse)>;
        const Sobol pixel(key, index_reversed, vw{});
        const vf fx = ((x + unit_lanes(pixel.x())) - 0.5) / real(width);
        const vf fy = ((y + unit_lanes(pixel.y())) + 0.5) / real(height);
        direction = vertex::pinhole_direction<Lanes>(camera, fx, fy);
        origin = {splat(camera.position.x), splat(camera.position.y), splat(camera.position.z)};
        if (lens) {  // camera.lens_radius > 0
            const Sobol numbers(key, index_reversed, vw{} + 1);
            vertex::thin_lens_ray<Lanes>(camera, V3(direction), unit_lanes(numbers.x()), unit_lanes(numbers.y()),
                                         origin, direction);
        }
    });
}

#ifdef KR_LANES_FLOAT
// Camera samples of Sobol samplers at their first dimension, known by their keys and
// reversed indices: their camera rays a vector at a time in single precision (camera_lanes),
// straight into the columns the lanes start their paths from, then trace_paths. One form per
// kind of scene (LaneScene), each with a trace_paths of its own (called once per chunk), and
// per camera (kLens: a thin lens, else a pinhole).
template <bool kWide, bool kLens>
void trace_camera_chunks(const RenderScene& scene, const RenderSettings& settings, int width, int height,
                         const int* xs, const int* ys, const uint32_t* keys, const uint32_t* index_reversed, int count,
                         SampleResult* results) {
    const CameraModel& camera = scene.camera;
    constexpr bool lens = kLens;
    constexpr int kChunk = kSampleBatch;
    for (int first = 0; first < count; first += kChunk) {
        const int n = std::min(kChunk, count - first);
        alignas(sizeof(vf)) float dir_x[kChunk + kLanes], dir_y[kChunk + kLanes], dir_z[kChunk + kLanes];
        alignas(sizeof(vf)) float o_x[kChunk + kLanes], o_y[kChunk + kLanes], o_z[kChunk + kLanes];
        for (int group = 0; group < n; group += kLanes) {
            const int at = first + group;
            vw key, index;
            vm x_int, y_int;
            if (group + kLanes <= n) {  // whole vectors of the columns
                __builtin_memcpy(&key, keys + at, sizeof key);
                __builtin_memcpy(&index, index_reversed + at, sizeof index);
                __builtin_memcpy(&x_int, xs + at, sizeof x_int);
                __builtin_memcpy(&y_int, ys + at, sizeof y_int);
            } else {  // lanes past the chunk's end repeat its first sample
                const auto sample = [&](size_t k) { return group + int(k) < n ? at + int(k) : first; };
                key = lanes_of<vw>([&](size_t k) { return keys[sample(k)]; });
                index = lanes_of<vw>([&](size_t k) { return index_reversed[sample(k)]; });
                x_int = lanes_of<vm>([&](size_t k) { return xs[sample(k)]; });
                y_int = lanes_of<vm>([&](size_t k) { return ys[sample(k)]; });
            }
            V3 origin, unit;
            camera_lanes(camera, lens, width, height, key, index, __builtin_convertvector(x_int, vf),
                         __builtin_convertvector(y_int, vf), origin, unit);
            __builtin_memcpy(dir_x + group, &unit.x, sizeof unit.x);
            __builtin_memcpy(dir_y + group, &unit.y, sizeof unit.y);
            __builtin_memcpy(dir_z + group, &unit.z, sizeof unit.z);
            if (lens) {
                __builtin_memcpy(o_x + group, &origin.x, sizeof origin.x);
                __builtin_memcpy(o_y + group, &origin.y, sizeof origin.y);
                __builtin_memcpy(o_z + group, &origin.z, sizeof origin.z);
            }
        }
        trace_paths<kWide>(scene, settings,
                           CameraColumns<kLens>{camera.position, dir_x, dir_y, dir_z, o_x, o_y, o_z, keys + first,
                                                index_reversed + first},
                           nullptr, n, results + first);
    }
}
void trace_sobol_camera_lanes(const RenderScene& scene, const RenderSettings& settings, int width, int height,
                              const int* xs, const int* ys, const uint32_t* keys, const uint32_t* index_reversed,
                              int count, SampleResult* results) {
    const bool lens = scene.camera.lens_radius > 0;
    const auto chunks = wide_scene(scene) ? (lens ? trace_camera_chunks<true, true> : trace_camera_chunks<true, false>)
                                          : (lens ? trace_camera_chunks<false, true> : trace_camera_chunks<false, false>);
    chunks(scene, settings, width, height, xs, ys, keys, index_reversed, count, results);
}
// The first surfaces of camera samples given as trace_sobol_camera_lanes takes them (their
// rays made by camera_lanes): the sphere each ray hits first (-1: none) and the unit normal
// there turned to face the ray, three floats a sample (the hit record of find_hits). The
// feature buffers' first hits (render/aov.h), a vector of samples at a time; lanes past
// `count` repeat the first sample.
template <bool kWide>
void camera_surfaces_of(const RenderScene& scene, int width, int height, const int* xs, const int* ys,
                        const uint32_t* keys, const uint32_t* index_reversed, int count, int* spheres,
                        float* normals) {
    LaneScene<kWide> lane_scene(scene);
    for (size_t s = 0; s < scene.spheres.size(); ++s) lane_scene.table.centre.set(s, scene.spheres[s].centre);
    const bool lens = scene.camera.lens_radius > 0;
    for (int group = 0; group < count; group += kLanes) {
        const int n = std::min(kLanes, count - group);
        const auto sample = [&](size_t k) { return group + (int(k) < n ? int(k) : 0); };
        const vw key = lanes_of<vw>([&](size_t k) { return keys[sample(k)]; });
        const vw index = lanes_of<vw>([&](size_t k) { return index_reversed[sample(k)]; });
        const vm x = lanes_of<vm>([&](size_t k) { return xs[sample(k)]; });
        const vm y = lanes_of<vm>([&](size_t k) { return ys[sample(k)]; });
        V3 origin, unit;
        camera_lanes(scene.camera, lens, width, height, key, index, __builtin_convertvector(x, vf),
                     __builtin_convertvector(y, vf), origin, unit);
        vf t;
        vm id;
        lane_scene.closest(origin, unit, vm{} - 1, vm{}, ~vm{}, t, id);
        // The outward normal at the hit (find_hits' record), then the side the ray meets.
        const vm hit_id = id >= 0 ? id : vm{};
        const vf reach = select(id >= 0, t, vf{});
        const V3 offset = (origin + unit * reach) - look_up(lane_scene.table.centre, hit_id);
        const vf offset_length = sqrt_lanes(dot(offset, offset));
        const V3 outward = select(offset_length > 0, offset * (1.0 / offset_length), -unit);
        const V3 facing = select(dot(unit, outward) < 0, outward, -outward);
        for (int k = 0; k < n; ++k) {
            spheres[group + k] = int(id[k]);
            normals[3 * (group + k)] = float(facing.x[k]);
            normals[3 * (group + k) + 1] = float(facing.y[k]);
            normals[3 * (group + k) + 2] = float(facing.z[k]);
        }
    }
}
void camera_surfaces(const RenderScene& scene, int width, int height, const int* xs, const int* ys,
                     const uint32_t* keys, const uint32_t* index_reversed, int count, int* spheres, float* normals) {
    (wide_scene(scene) ? camera_surfaces_of<true> : camera_surfaces_of<false>)(scene, width, height, xs, ys, keys,
                                                                                 index_reversed, count, spheres, normals);
}
// The same for Sobol samplers: their keys and indices read, and the samplers moved past the
// camera's dimensions, as one path's camera ray moves them.
void trace_camera_lanes(const RenderScene& scene, const RenderSettings& settings, int width, int height,
                        const int* xs, const int* ys, Sampler* const* samplers, int count, SampleResult* results) {
    for (int first = 0; first < count; first += kSampleBatch) {
        const int n = std::min(kSampleBatch, count - first);
        uint32_t keys[kSampleBatch], index_reversed[kSampleBatch];
        for (int k = 0; k < n; ++k) {
            keys[k] = samplers[first + k]->sobol_key();
            index_reversed[k] = samplers[first + k]->index_reversed();
            samplers[first + k]->skip_dimensions(2);  // the pixel, the lens
        }
        trace_sobol_camera_lanes(scene, settings, width, height, xs + first, ys + first, keys, index_reversed, n,
                                 results + first);
    }
}
#endif

#ifndef KR_LANES_FLOAT  // the float lanes take the camera rays of the double ones
// camera_rays for a thin lens (kLens) or a pinhole: each form compiled alone.
template <bool kLens>
void camera_rays_of(const RenderScene& scene, int width, int height, const int* xs, const int* ys,
                    Sampler* const* samplers, int count, Ray* rays) {
    const CameraModel& camera = scene.camera;
    for (int first = 0; first < count; first += 4) {
        const int n = std::min(4, count - first);
        bool lanes = true;
        for (int k = first; k < first + n; ++k) lanes &= samplers[k]->sobol() && samplers[k]->dimension() == 0;
        if (!lanes) {
            for (int k = first; k < first + n; ++k) rays[k] = camera_ray(scene, width, height, xs[k], ys[k], *samplers[k]);
            continue;
        }
        // Lanes past `n` repeat the first sample.
        vw key, index_reversed;
        vf x, y;
        for (int k = 0; k < kLanes; ++k) {
            const int i = first + (k < n ? k : 0);
            key[k] = samplers[i]->sobol_key();
            index_reversed[k] = samplers[i]->index_reversed();
            x[k] = xs[i], y[k] = ys[i];
        }
        for (int k = first; k < first + n; ++k) samplers[k]->skip_dimensions(2);  // the pixel, the lens
        V3 origin, unit;
        camera_lanes(camera, kLens, width, height, key, index_reversed, x, y, origin, unit);
        for (int k = 0; k < n; ++k) {
            Ray& ray = rays[first + k];
            ray = Ray();
            ray.o = kLens ? lane(origin, k) : camera.position;
            ray.d = lane(unit, k);
        }
    }
}
void camera_rays(const RenderScene& scene, int width, int height, const int* xs, const int* ys,
                 Sampler* const* samplers, int count, Ray* rays) {
    (scene.camera.lens_radius > 0 ? camera_rays_of<true> : camera_rays_of<false>)(scene, width, height, xs, ys,
                                                                                    samplers, count, rays);
}
#endif

// A batch's samples added to the pixel sums, at this target's level: last, as it keeps
// products unfused to the end of the file (KR_UNFUSED_BEGIN, levels.h).
#include "render/lanes/accumulate.h"

// This target's entry points, for lanes.cpp.
#ifdef KR_LANES_FLOAT
const TargetKernels kernels{true,           nullptr,         trace_lanes, trace_sobol_camera_lanes, trace_camera_lanes,
                            accumulate_batch, closest_spheres, camera_surfaces};
#else
const TargetKernels kernels{true,           camera_rays, trace_lanes, nullptr, nullptr, accumulate_batch,
                            closest_spheres, nullptr};
#endif

}  // namespace kr::lanes::KR_LANE_TARGET
KR_LEVEL_END
#endif
