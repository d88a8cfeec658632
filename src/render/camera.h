// Pinhole and thin-lens cameras in the scene's left-handed frame (right = up x forward).
#pragma once

#include "core/math.h"
#include "scene/scene.h"

namespace kr {

struct CameraRay {
    Vec3 origin, direction;  // direction is unit length
};

struct CameraModel {
    Vec3 position, forward, right, up;
    double tan_half_fov = 0.41421356237;  // tan(fov_y / 2)
    double aspect = 1;
    double lens_radius = 0;     // 0: pinhole
    double focal_distance = 1;  // distance of the plane in focus, along forward

    // Throws std::invalid_argument if position equals target or a value is not finite.
    static CameraModel from(const Camera& camera);

    // (fx, fy) in [0,1)^2 over the image, fx to the right, fy downwards.
    // (u1, u2) pick the point on the lens (ignored for a pinhole).
    CameraRay generate(double fx, double fy, double u1, double u2) const;
};

}  // namespace kr
