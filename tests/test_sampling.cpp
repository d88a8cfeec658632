// Sampling routines: chi-square tests of their distributions, moments, and the estimators.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <vector>

#include "core/rng.h"
#include "core/sampling.h"
#include "render/lanes/lanes.h"
#include "render/light.h"
#include "render/settings.h"
#include "test_util.h"

using namespace kr;

namespace {

// Chi-square test of a direction sampler against a density over (cos theta, phi) cells.
// The expected count of each cell integrates the density numerically.
void expect_directions_follow(const std::function<Vec3(double, double)>& sample,
                              const std::function<double(const Vec3&)>& pdf, double z_min = -1,
                              int samples = 200000) {
    // Cells split [z_min, 1] x [0, 2 pi): aligned with a cone's edge so no cell straddles it.
    constexpr int kTheta = 16, kPhi = 32;
    std::vector<double> observed(kTheta * kPhi, 0.0), expected(kTheta * kPhi, 0.0);
    auto cell_of = [z_min](const Vec3& d) {
        const double z = std::clamp(d.z, -1.0, 1.0);
        int it = std::clamp(int((1 - z) / (1 - z_min) * kTheta), 0, kTheta - 1);
        double phi = std::atan2(d.y, d.x);
        if (phi < 0) phi += 2 * kPi;
        int ip = std::min(kPhi - 1, int(phi / (2 * kPi) * kPhi));
        return it * kPhi + ip;
    };
    Rng rng(11, 5);
    for (int i = 0; i < samples; ++i) observed[cell_of(sample(rng.next(), rng.next()))] += 1;
    // Integrate pdf over each cell in (z, phi), where d(omega) = dz dphi.
    constexpr int kSub = 8;
    for (int it = 0; it < kTheta; ++it)
        for (int ip = 0; ip < kPhi; ++ip) {
            double sum = 0;
            for (int a = 0; a < kSub; ++a)
                for (int b = 0; b < kSub; ++b) {
                    const double z = 1 - (1 - z_min) * (it + (a + 0.5) / kSub) / kTheta;
                    const double phi = 2 * kPi * (ip + (b + 0.5) / kSub) / kPhi;
                    const double r = std::sqrt(std::max(0.0, 1 - z * z));
                    sum += pdf({r * std::cos(phi), r * std::sin(phi), z});
                }
            const double cell_area = ((1 - z_min) / kTheta) * (2 * kPi / kPhi);
            expected[it * kPhi + ip] = sum / (kSub * kSub) * cell_area * samples;
        }
    // Merge cells expected to hold fewer than 5 samples into one.
    std::vector<double> obs, exp;
    double obs_rest = 0, exp_rest = 0;
    for (size_t i = 0; i < observed.size(); ++i) {
        if (expected[i] < 5) {
            obs_rest += observed[i];
            exp_rest += expected[i];
        } else {
            obs.push_back(observed[i]);
            exp.push_back(expected[i]);
        }
    }
    if (exp_rest >= 5) {
        obs.push_back(obs_rest);
        exp.push_back(exp_rest);
    } else {
        EXPECT_LE(obs_rest, 20) << "samples where the density is ~0";
    }
    const double stat = test::chi_square(obs, exp);
    EXPECT_LT(stat, test::chi_square_critical(int(obs.size()) - 1)) << "cells " << obs.size();
}

}  // namespace

TEST(Sampling, RngIsUniformAndStreamsDiffer) {
    Rng rng(1, 2);
    constexpr int kBins = 64, kN = 640000;
    std::vector<double> counts(kBins, 0);
    double mean = 0;
    for (int i = 0; i < kN; ++i) {
        const double u = rng.next();
        ASSERT_GE(u, 0.0);
        ASSERT_LT(u, 1.0);
        counts[int(u * kBins)] += 1;
        mean += u;
    }
    EXPECT_NEAR(mean / kN, 0.5, 4 * std::sqrt(1.0 / 12 / kN));
    EXPECT_LT(test::chi_square(counts, std::vector<double>(kBins, double(kN) / kBins)),
              test::chi_square_critical(kBins - 1));
    // Neighbouring pixels and samples get unrelated streams.
    Rng a = Rng::for_sample(0, 100, 0), b = Rng::for_sample(0, 101, 0), c = Rng::for_sample(0, 100, 1);
    EXPECT_NE(a.next_u32(), b.next_u32());
    EXPECT_NE(Rng::for_sample(0, 100, 0).next_u32(), c.next_u32());
    // Same inputs, same stream.
    EXPECT_EQ(Rng::for_sample(9, 5, 3).next_u32(), Rng::for_sample(9, 5, 3).next_u32());
}

TEST(Sampling, CosineHemisphereChiSquare) {
    expect_directions_follow([](double u1, double u2) { return sample_cosine_hemisphere(u1, u2); },
                             [](const Vec3& d) { return cosine_hemisphere_pdf(d.z); });
}

TEST(Sampling, UniformSphereChiSquare) {
    expect_directions_follow([](double u1, double u2) { return sample_uniform_sphere(u1, u2); },
                             [](const Vec3&) { return uniform_sphere_pdf(); });
}

TEST(Sampling, UniformConeChiSquare) {
    for (double theta_max : {0.3, 1.2}) {
        const double omc = 1 - std::cos(theta_max);
        expect_directions_follow([&](double u1, double u2) { return sample_uniform_cone(u1, u2, omc); },
                                 [&](const Vec3&) { return uniform_cone_pdf(omc); }, 1 - omc);
    }
}

TEST(Sampling, ConcentricDiskIsUniform) {
    Rng rng(4, 4);
    constexpr int kN = 200000, kRings = 10, kSectors = 16;
    std::vector<double> counts(kRings * kSectors, 0);
    for (int i = 0; i < kN; ++i) {
        const Vec2 p = sample_concentric_disk(rng.next(), rng.next());
        const double r2 = p.x * p.x + p.y * p.y;
        ASSERT_LE(r2, 1.0 + 1e-12);
        double phi = std::atan2(p.y, p.x);
        if (phi < 0) phi += 2 * kPi;
        // Rings of equal area: r^2 uniform.
        counts[std::min(kRings - 1, int(r2 * kRings)) * kSectors + std::min(kSectors - 1, int(phi / (2 * kPi) * kSectors))] += 1;
    }
    EXPECT_LT(test::chi_square(counts, std::vector<double>(counts.size(), double(kN) / counts.size())),
              test::chi_square_critical(int(counts.size()) - 1));
}

// The brief's perturbation: P is a uniform point on the sphere of radius beta, so its mean
// is zero and its second moment beta^2.
TEST(Sampling, PerturbationMoments) {
    Rng rng(8, 8);
    const double beta = 0.4;
    Vec3 mean;
    double second = 0;
    constexpr int kN = 100000;
    for (int i = 0; i < kN; ++i) {
        const Vec3 p = perturbation(beta, rng.next(), rng.next());
        EXPECT_NEAR(length(p), beta, 1e-12);
        mean += p;
        second += dot(p, p);
    }
    mean /= kN;
    EXPECT_LT(length(mean), 4 * beta / std::sqrt(3.0 * kN) * std::sqrt(3.0));
    EXPECT_NEAR(second / kN, beta * beta, 1e-12);
    // Roughness 0 leaves the mirror direction unchanged.
    EXPECT_EQ(perturb_direction(Vec3(0, 0, 1), 0.0, 0.3, 0.7), Vec3(0, 0, 1));
}

// Light sampling returns directions with the density it claims: the estimator of the solid
// angle a sphere subtends, 1/pdf averaged, must match 2 pi (1 - cos theta_max).
TEST(Sampling, SphereLightDensitiesIntegrateToSolidAngle) {
    const SphereGeom light{{0, 0, 4}, 1};
    const Vec3 p{0.3, -0.2, 0};
    const double d = length(light.centre - p);
    const double solid_angle = 2 * kPi * (1 - std::sqrt(1 - 1 / (d * d)));
    for (LightSampling strategy : {LightSampling::cone, LightSampling::area}) {
        Rng rng(2, 9);
        double sum = 0, sum_sq = 0;
        constexpr int kN = 200000;
        for (int i = 0; i < kN; ++i) {
            LightSample ls;
            double v = 0;
            if (sample_sphere_light(light, p, strategy, rng.next(), rng.next(), ls)) {
                v = 1 / ls.pdf;
                // The sampled point lies on the sphere, on the side facing p.
                const Vec3 y = p + ls.distance * ls.wi;
                EXPECT_NEAR(length(y - light.centre), 1, 1e-9);
                const Vec3 n = normalize(y - light.centre);
                // And the pdf function agrees with the sampler's pdf.
                EXPECT_NEAR(sphere_light_pdf(light, p, ls.wi, ls.distance, n, strategy), ls.pdf, ls.pdf * 1e-9);
            }
            sum += v;
            sum_sq += v * v;
        }
        const double mean = sum / kN, sigma = std::sqrt(std::max(0.0, sum_sq / kN - mean * mean) / kN);
        EXPECT_NEAR(mean, solid_angle, 4 * sigma + 1e-9 * solid_angle) << light_sampling_names.name(strategy);
    }
}

// From inside a light, uniform area sampling covers all directions: 1/pdf averages to 4 pi.
TEST(Sampling, SphereLightFromInside) {
    const SphereGeom light{{0, 0, 0}, 2};
    const Vec3 p{0.5, 0.3, -0.4};
    Rng rng(5, 5);
    double sum = 0;
    constexpr int kN = 200000;
    for (int i = 0; i < kN; ++i) {
        LightSample ls;
        ASSERT_TRUE(sample_sphere_light(light, p, LightSampling::cone, rng.next(), rng.next(), ls));
        sum += 1 / ls.pdf;
    }
    EXPECT_NEAR(sum / kN, 4 * kPi, 0.05);
}

// The brief's stratified estimator puts exactly one sample in each of the e x e strata.
TEST(Sampling, StratifiedEstimatorCoversEveryStratum) {
    for (int target : {1, 4, 8, 9, 36, 50}) {
        const int e = int(std::sqrt(double(target)));
        std::vector<int> hits(e * e, 0);
        for (int i = 0; i < e * e; ++i) {
            const Vec2 s = Sampler(Estimator::stratified, 1, 0, i, target).pixel();
            ASSERT_GE(s.x, 0);
            ASSERT_LT(s.x, 1);
            hits[int(s.y * e) * e + int(s.x * e)] += 1;
        }
        for (int h : hits) EXPECT_EQ(h, 1) << "target " << target;
        // Samples past e^2 (non-square counts) are uniform over the pixel.
        for (int i = e * e; i < target; ++i) {
            const Vec2 s = Sampler(Estimator::stratified, 1, 0, i, target).pixel();
            EXPECT_TRUE(s.x >= 0 && s.x < 1 && s.y >= 0 && s.y < 1);
        }
    }
}

// Both estimators integrate a smooth function over the pixel without bias; stratified with
// lower error.
TEST(Sampling, EstimatorsAreUnbiasedAndStratifiedIsBetter) {
    auto f = [](Vec2 p) { return std::sin(3 * p.x) * std::exp(p.y); };
    const double exact = (1 - std::cos(3.0)) / 3 * (std::exp(1.0) - 1);
    double err[2] = {0, 0};
    double mean[2] = {0, 0};
    constexpr int kTrials = 2000, kSpp = 16;
    for (Estimator est : {Estimator::uniform, Estimator::stratified}) {
        for (int t = 0; t < kTrials; ++t) {
            double sum = 0;
            for (int i = 0; i < kSpp; ++i) {
                sum += f(Sampler(est, 3, t, i, kSpp).pixel());
            }
            const double estimate = sum / kSpp;
            mean[int(est)] += estimate / kTrials;
            err[int(est)] += (estimate - exact) * (estimate - exact) / kTrials;
        }
    }
    EXPECT_NEAR(mean[0], exact, 4 * std::sqrt(err[0] / kTrials));
    EXPECT_NEAR(mean[1], exact, 4 * std::sqrt(err[1] / kTrials) + 1e-9);
    EXPECT_LT(err[1], err[0] / 4);
}

// The brief's light estimator (the references' own): exact for distant lights, brighter
// than the exact irradiance close to a light, by the factor measured on the references
// (about 1.5 directly facing a light at 3 radii).
TEST(Sampling, BriefLightEstimatorBias) {
    auto irradiance_ratio = [](double distance) {
        const SphereGeom light{{0, distance, 0}, 1};
        const Vec3 p{0, 0, 0}, n{0, 1, 0};
        Rng rng(6, 6);
        double sum = 0;
        constexpr int kN = 400000;
        for (int i = 0; i < kN; ++i) {
            LightSample ls;
            if (sample_sphere_light(light, p, LightSampling::brief, rng.next(), rng.next(), ls))
                sum += std::max(0.0, dot(ls.wi, n)) / ls.pdf;
        }
        const double exact = kPi / (distance * distance);  // pi sin^2(theta_max), L = 1
        return sum / kN / exact;
    };
    EXPECT_NEAR(irradiance_ratio(1000), 1.0, 0.01);
    const double near = irradiance_ratio(3);
    EXPECT_GT(near, irradiance_ratio(10));
    EXPECT_GT(near, 1.4);
    EXPECT_LT(near, 1.65);
}

TEST(Sampling, SinCosTurnsMatchesLibm) {
    Rng rng(7, 1);
    double worst = 0;
    for (int i = 0; i < 200000; ++i) {
        // Whole turns, their boundaries and values outside [0, 1) (the disk mapping uses -1/8..3/8).
        const double t = i < 16 ? i / 8.0 - 1.0 : 4.0 * rng.next() - 2.0;
        double s, c;
        sin_cos_turns(t, s, c);
        worst = std::max({worst, std::abs(s - std::sin(2 * kPi * t)), std::abs(c - std::cos(2 * kPi * t))});
    }
    EXPECT_LT(worst, 2e-15);
}

TEST(Sampling, LogMatchesLibmOnOneDoubleAndOnLanes) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    Rng rng(11, 3);
    double worst_ulps = 0;
    for (int i = 0; i < 200000; ++i) {
        // Mantissas across [1, 2) at exponents over the whole normal range, and values near 1.
        const double x = i % 4 == 0 ? 1.0 + (rng.next() - 0.5) * 1e-3
                                    : (1.0 + rng.next()) * std::ldexp(1.0, int(rng.next() * 2044) - 1022);
        const double exact = std::log(x), got = log_positive(x);
        const double ulp = std::nextafter(std::abs(exact), kInf) - std::abs(exact);
        worst_ulps = std::max(worst_ulps, std::abs(got - exact) / ulp);
        // Four lanes give what one double gives.
        const v4d lanes = log_normal_positive<v4d, v4u>(v4d{x, 2 * x, 0.5 * x, x});
        ASSERT_EQ(lanes[0], got);
        ASSERT_EQ(lanes[3], got);
    }
    EXPECT_LE(worst_ulps, 1.0);
    EXPECT_EQ(log_positive(1.0), 0.0);
    EXPECT_EQ(log_positive(2.0), std::log(2.0));
    // Outside the normal range it answers as libm does.
    EXPECT_EQ(log_positive(0.0), -kInf);
    EXPECT_EQ(log_positive(kInf), kInf);
    EXPECT_TRUE(std::isnan(log_positive(-1.0)));
    EXPECT_EQ(log_positive(0x1.0p-1070), std::log(0x1.0p-1070));
    std::printf("log_positive: worst error %.2f ulp\n", worst_ulps);
}

// The brief's light integral, int over the hemisphere facing p of cos_i cos_axis / dist^2 dA,
// by midpoint quadrature in (theta, phi) about the axis, with rings crowded towards the pole
// (theta = pi/2 t^2) where the integrand peaks for a close receiver.
double brief_integral_quadrature(const SphereGeom& light, const Vec3& p, const Vec3& n_receiver) {
    const Vec3 axis = normalize(p - light.centre);
    const Frame frame = Frame::from_normal(axis);
    constexpr int kRings = 3000, kSectors = 360;
    double sum = 0;
    for (int i = 0; i < kRings; ++i) {
        const double t = (i + 0.5) / kRings, theta = 0.5 * kPi * t * t, dtheta = kPi * t / kRings;
        for (int j = 0; j < kSectors; ++j) {
            const double phi = 2 * kPi * (j + 0.5) / kSectors;
            const Vec3 n = frame.to_world({std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)});
            const Vec3 w = light.centre + light.radius * n - p;
            const double d2 = dot(w, w);
            const double cos_i = std::max(0.0, dot(w, n_receiver) / std::sqrt(d2));
            // dA = r^2 sin(theta) dtheta dphi.
            sum += cos_i * std::cos(theta) / d2 * std::sin(theta) * dtheta;
        }
    }
    return sum * light.radius * light.radius * (2 * kPi / kSectors);
}

// One-sample mean and standard deviation of an estimator over n samples.
struct Moments {
    double mean, sd;
};
template <typename F>
Moments moments(F sample, int n) {
    double sum = 0, sum_sq = 0;
    for (int i = 0; i < n; ++i) {
        const double v = sample();
        sum += v;
        sum_sq += v * v;
    }
    const double mean = sum / n;
    return {mean, std::sqrt(std::max(0.0, sum_sq / n - mean * mean))};
}

// The brief's light estimator draws its points close to cos_axis / dist^2: the same integral
// as the brief's uniform hemisphere sampling, from just above the surface to far away, with
// a far smaller variance.
TEST(Sampling, BriefLightImportanceSamplingKeepsTheBriefIntegral) {
    const SphereGeom light{{0, 0, 0}, 1};
    constexpr int kN = 200000;
    for (double distance : {1.02, 1.3, 3.0, 10.0}) {
        for (double tilt : {0.0, 1.2}) {
            const Vec3 p{0, distance, 0};
            const Vec3 n_receiver = normalize(Vec3{std::sin(tilt), -std::cos(tilt), 0});
            const double exact = brief_integral_quadrature(light, p, n_receiver);
            Rng rng(11, 3);
            const Moments importance = moments([&] {
                LightSample ls;
                const double u1 = rng.next(), u2 = rng.next();
                if (!sample_sphere_light(light, p, LightSampling::brief, u1, u2, ls)) return 0.0;
                return std::max(0.0, dot(ls.wi, n_receiver)) / ls.pdf;
            }, kN);
            // The brief's own sampling: y uniform on the facing hemisphere, weight
            // cos_i cos_axis (A/2) / dist^2.
            const Moments hemisphere = moments([&] {
                const double u1 = rng.next(), u2 = rng.next();
                Vec3 n = sample_uniform_sphere(u1, u2);
                if (n.y < 0) n = -n;
                const Vec3 w = light.centre + n - p;
                const double d2 = dot(w, w);
                return std::max(0.0, dot(w, n_receiver) / std::sqrt(d2)) * n.y * (2 * kPi) / d2;
            }, kN);
            EXPECT_NEAR(importance.mean, exact, 4 * importance.sd / std::sqrt(double(kN)) + 2e-3 * exact)
                << "distance " << distance << " tilt " << tilt;
            // Close to the light the hemisphere sampling is too heavy-tailed for its sample
            // mean to be checked (at 1.02 radii its standard deviation is 15x the mean's).
            if (distance >= 3)
                EXPECT_NEAR(hemisphere.mean, exact, 4 * hemisphere.sd / std::sqrt(double(kN)) + 2e-3 * exact)
                    << "distance " << distance << " tilt " << tilt;
            EXPECT_LT(importance.sd, hemisphere.sd) << "distance " << distance << " tilt " << tilt;
            // Facing a far light straight on, cos_i stays near 1 over its small cap and the
            // points follow cos_axis / dist^2 closely.
            if (tilt == 0 && distance >= 10) EXPECT_LT(importance.sd, 0.1 * importance.mean) << "distance " << distance;
        }
    }
}

// The brief strategy's points: chi-square of cos_axis (the cosine between the point's normal and
// the axis from the light's centre to p) against its density on [0, 1], alpha 2u +
// (1 - alpha) b / ((a - b u) v) with v = ln(a / (a - b)) and alpha = 1 / (1 + v^3).
TEST(Sampling, BriefLightPointsFollowTheirDensity) {
    const SphereGeom light{{0, 0, 0}, 1};
    for (double distance : {1.01, 1.5, 4.0, 40.0}) {
        const double a = distance * distance + 1, b = 2 * distance, v = std::log(a / (a - b)),
                     alpha = 1 / (1 + v * v * v);
        auto density = [&](double u) { return alpha * 2 * u + (1 - alpha) * b / ((a - b * u) * v); };
        constexpr int kBins = 40, kN = 200000;
        // Expected bin probabilities by fine midpoint quadrature of the density.
        std::vector<double> expected(kBins, 0.0);
        double total = 0;
        for (int i = 0; i < kBins * 1000; ++i) {
            const double u = (i + 0.5) / (kBins * 1000);
            expected[i / 1000] += density(u);
            total += density(u);
        }
        std::vector<int> observed(kBins, 0);
        Rng rng(21, 5);
        const Vec3 p{0, 0, distance};
        for (int i = 0; i < kN; ++i) {
            LightSample ls;
            ASSERT_TRUE(sample_sphere_light(light, p, LightSampling::brief, rng.next(), rng.next(), ls));
            const Vec3 y = p + ls.distance * ls.wi;
            const double cos_axis = std::clamp(y.z, 0.0, 1.0 - 1e-12);
            observed[int(cos_axis * kBins)] += 1;
        }
        double chi2 = 0;
        for (int k = 0; k < kBins; ++k) {
            const double e = expected[k] / total * kN;
            chi2 += (observed[k] - e) * (observed[k] - e) / e;
        }
        EXPECT_LT(chi2, 73.4) << "distance " << distance;  // p = 0.001 for 39 degrees of freedom
    }
}
