// Embree's BVH for scenes of more than 32 spheres (AccelBackend, accel.h). Embree traverses
// its boxes in single precision; every sphere it reaches is tested by the same double-
// precision rules as the plain path (accepted_root), through user-geometry callbacks, so the
// hits are exact and the same as our own BVH's. Built only where CMake found libembree-dev,
// as the module keithray_embree.so (core/module.h): the program loads it, and with it
// libembree3 and TBB, the first time a scene is given to Embree.
#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <new>
#include <stdexcept>
#include <string>

#include "render/accel.h"
#include "render/render_scene.h"

namespace kr {

struct EmbreeSpheres {
    std::vector<SphereGeom> spheres;  // its own copy: the callbacks read it
    double extent = 0;                // every sphere lies within this distance of the origin
    float pad = 0;                    // each sphere's box grows by this (see build)
    RTCScene scene = nullptr;

    EmbreeSpheres() = default;
    EmbreeSpheres(const EmbreeSpheres&) = delete;
    EmbreeSpheres& operator=(const EmbreeSpheres&) = delete;
    ~EmbreeSpheres() {
        if (scene) rtcReleaseScene(scene);
    }
};

namespace {

// The program's double-precision sphere test (render_scene.h), passed by the loader.
const EmbreeHost* g_host = nullptr;

// One device for the process: it holds Embree's settings and, for builds, its threads. One
// build thread: the renderer's OpenMP threads are busy when the viewer rebuilds after an
// edit, and a 100,000-sphere build takes about 0.1 s on one.
RTCDevice device() {
    static RTCDevice d = [] {
        RTCDevice made = rtcNewDevice("threads=1");
        if (!made) {
            const RTCError error = rtcGetDeviceError(nullptr);
            // Out of memory is said as such by the caller (core/memory.h is_out_of_memory).
            if (error == RTC_ERROR_OUT_OF_MEMORY) throw std::bad_alloc();
            throw std::runtime_error("Embree: cannot create a device (error " + std::to_string(int(error)) + ")");
        }
        return made;
    }();
    return d;
}

// What the callbacks need beside Embree's single-precision ray: the exact ray (its tmax the
// closest hit so far) and the nearest accepted sphere. Embree passes the context it was given,
// so ours starts with its own.
struct QueryContext {
    RTCIntersectContext base;
    const EmbreeSpheres* accel;
    Ray ray;
    double shift;  // Embree's ray starts this far along ours (see embree_ray)
    int best = -1;
};

void sphere_bounds(const RTCBoundsFunctionArguments* args) {
    const EmbreeSpheres& a = *static_cast<const EmbreeSpheres*>(args->geometryUserPtr);
    const SphereGeom& s = a.spheres[args->primID];
    const double lo[3] = {s.centre.x - s.radius, s.centre.y - s.radius, s.centre.z - s.radius};
    const double hi[3] = {s.centre.x + s.radius, s.centre.y + s.radius, s.centre.z + s.radius};
    // Rounded outwards, then padded: Embree's float ray and box tests must never cull a
    // sphere that the double test would hit.
    float* out_lo[3] = {&args->bounds_o->lower_x, &args->bounds_o->lower_y, &args->bounds_o->lower_z};
    float* out_hi[3] = {&args->bounds_o->upper_x, &args->bounds_o->upper_y, &args->bounds_o->upper_z};
    for (int k = 0; k < 3; ++k) {
        *out_lo[k] = std::nextafter(float(lo[k]), -INFINITY) - a.pad;
        *out_hi[k] = std::nextafter(float(hi[k]), INFINITY) + a.pad;
    }
}

void sphere_intersect(const RTCIntersectFunctionNArguments* args) {
    if (!args->valid[0]) return;
    QueryContext& q = *reinterpret_cast<QueryContext*>(args->context);
    const int index = int(args->primID);
    const double t = g_host->accepted_root(q.accel->spheres[size_t(index)], index, q.ray, false);
    // Ties keep the first found (t <= tmax is accepted, so a later equal root is not taken).
    if (!(t < kInfinity) || (q.best >= 0 && !(t < q.ray.tmax))) return;
    q.ray.tmax = t;
    q.best = index;
    // Embree culls boxes beyond its tfar: rounded up, so none that could hold a nearer root.
    RTCRayHit& rh = *reinterpret_cast<RTCRayHit*>(args->rayhit);
    rh.ray.tfar = std::nextafter(float(std::max(0.0, t - q.shift)), INFINITY);
    rh.hit.geomID = args->geomID;
    rh.hit.primID = args->primID;
}

void sphere_occluded(const RTCOccludedFunctionNArguments* args) {
    if (!args->valid[0]) return;
    QueryContext& q = *reinterpret_cast<QueryContext*>(args->context);
    const int index = int(args->primID);
    if (g_host->accepted_root(q.accel->spheres[size_t(index)], index, q.ray, true) < kInfinity) {
        q.best = index;
        reinterpret_cast<RTCRay*>(args->ray)->tfar = -INFINITY;  // Embree's "occluded"
    }
}

// Embree's single-precision copy of `ray`, or false when the ray cannot meet any sphere. A ray
// from outside the spheres' extent starts where it could first meet one (no sphere point is
// nearer the origin than `extent`, and the ray's point at t is at least |o| - t from it), so
// that its float origin stays as accurate as the boxes' padding assumes. A ray that meets the
// extent's ball has its shifted origin within sqrt(2) extents of the origin (between the
// origin and the line's nearest point to the centre); the others miss, and go no further:
// their shifted origins could leave Embree's valid range (camera 1e30 away, looking away).
bool embree_ray(const EmbreeSpheres& a, const Ray& ray, QueryContext& q, RTCRay& out) {
    const double origin_distance = length(ray.o);
    q.shift = std::max(0.0, origin_distance - a.extent);
    if (q.shift > 0) {
        const double along = dot(ray.o, ray.d);  // d is unit: the ray nears the origin while along < 0
        const Vec3 nearest = ray.o - along * ray.d;
        // The nearest point rounds by a few ulps of |o|: only lines clearly outside are culled.
        const double reach = a.extent * (1 + 0x1.0p-20) + 0x1.0p-48 * origin_distance;
        if (along >= 0 || dot(nearest, nearest) > reach * reach) return false;
    }
    const Vec3 o = ray.o + q.shift * ray.d;
    out.org_x = float(o.x);
    out.org_y = float(o.y);
    out.org_z = float(o.z);
    out.dir_x = float(ray.d.x);
    out.dir_y = float(ray.d.y);
    out.dir_z = float(ray.d.z);
    out.tnear = std::max(0.0f, std::nextafter(float(ray.tmin - q.shift), -INFINITY));
    out.tfar = ray.tmax < kInfinity ? std::nextafter(float(std::max(0.0, ray.tmax - q.shift)), INFINITY) : INFINITY;
    out.time = 0;
    out.mask = ~0u;
    out.id = 0;
    out.flags = 0;
    return true;
}

}  // namespace

namespace {

std::shared_ptr<const EmbreeSpheres> build_embree_spheres(const std::vector<SphereGeom>& spheres) {
    auto a = std::make_shared<EmbreeSpheres>();
    a->spheres = spheres;
    for (const SphereGeom& s : spheres) a->extent = std::max(a->extent, length(s.centre) + s.radius);
    if (!(a->extent >= kEmbreeExtentMin && a->extent <= kEmbreeExtentMax)) {
        char message[160];
        std::snprintf(message, sizeof message,
                      "Embree: spheres reach %.3g from the origin, outside the %.3g to %.3g its single-precision "
                      "boxes hold",
                      a->extent, kEmbreeExtentMin, kEmbreeExtentMax);
        throw std::runtime_error(message);
    }
    // Float rounding of the ray (shifted within 1.5 extents of the origin, see embree_ray) and
    // of Embree's slab tests moves a box test by under 2^-20 of the extent; the pad is four
    // times that.
    a->pad = float(std::ldexp(a->extent, -18));
    a->scene = rtcNewScene(device());
    // Static scene, traced many times: the better tree is worth the slower build.
    rtcSetSceneBuildQuality(a->scene, RTC_BUILD_QUALITY_HIGH);
    rtcSetSceneFlags(a->scene, RTC_SCENE_FLAG_ROBUST);
    RTCGeometry geometry = rtcNewGeometry(device(), RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(geometry, unsigned(spheres.size()));
    rtcSetGeometryUserData(geometry, a.get());
    rtcSetGeometryBoundsFunction(geometry, sphere_bounds, a.get());
    rtcSetGeometryIntersectFunction(geometry, sphere_intersect);
    rtcSetGeometryOccludedFunction(geometry, sphere_occluded);
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(a->scene, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(a->scene);
    const RTCError error = rtcGetDeviceError(device());
    // A scene whose commit failed is left to the process, not released: Embree's destructor
    // of it ends the process (std::terminate in its build's task group), which the error
    // said here would never reach. Memory ran out: the process is ending or drops the scene.
    if (error != RTC_ERROR_NONE) a->scene = nullptr;
    if (error == RTC_ERROR_OUT_OF_MEMORY) throw std::bad_alloc();
    if (error != RTC_ERROR_NONE)
        throw std::runtime_error("Embree: building the BVH of " + std::to_string(spheres.size()) +
                                 " spheres failed (error " + std::to_string(int(error)) + ")");
    return a;
}

int embree_closest(const EmbreeSpheres& accel, const Ray& ray, double& t) {
    QueryContext q;
    rtcInitIntersectContext(&q.base);
    q.accel = &accel;
    q.ray = ray;
    RTCRayHit rh;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    if (embree_ray(accel, ray, q, rh.ray)) rtcIntersect1(accel.scene, &q.base, &rh);
    t = q.best >= 0 ? q.ray.tmax : ray.tmax;
    return q.best;
}

bool embree_any(const EmbreeSpheres& accel, const Ray& ray) {
    QueryContext q;
    rtcInitIntersectContext(&q.base);
    q.accel = &accel;
    q.ray = ray;
    RTCRay r;
    if (embree_ray(accel, ray, q, r)) rtcOccluded1(accel.scene, &q.base, &r);
    return q.best >= 0;
}

constexpr EmbreeModule kModule{build_embree_spheres, embree_closest, embree_any, KEITHRAY_EMBREE_VERSION};

}  // namespace

}  // namespace kr

// The module's entry point (core/module.h).
extern "C" __attribute__((visibility("default"))) const void* keithray_embree_module(const char* version,
                                                                                    const void* host) {
    if (std::strcmp(version, KEITHRAY_MODULE_VERSION) != 0 || !host) return nullptr;
    kr::g_host = static_cast<const kr::EmbreeHost*>(host);
    return &kr::kModule;
}
