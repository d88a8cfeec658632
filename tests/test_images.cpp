// Image tests against the brief's reference renders (res/references), and a check that a
// wrong radiometric convention fails them.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/image.h"
#include "core/image_io.h"
#include "render/progressive.h"
#include "render/trace.h"
#include "scene/load.h"

using namespace kr;

namespace {

const std::string kRes = KEITHRAY_RES_DIR;

Scene load(int n) {
    return load_scene_file(kRes + "/scenes/assignment_0" + std::to_string(n) + ".json").scene;
}

Rgb8Image reference(int n) {
    return read_ppm(kRes + "/references/assignment_0" + std::to_string(n) + ".ppm");
}

Rgb8Image render(const Scene& authored, int spp) {
    const RenderScene scene = prepare_scene(authored);
    RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    settings.target_spp = spp;
    RenderState state(scene.renderer.width, scene.renderer.height);
    for (int i = 0; i < spp; ++i) render_pass(scene, settings, state);
    return tonemap(state.radiance(), ToneMap::sigmoid);
}

// Averages b x b blocks of 8-bit values: a low-sample render's noise shrinks by b while
// a wrong brightness, colour or shadow survives.
Rgb8Image block_average(const Rgb8Image& img, int b) {
    Rgb8Image out{img.width / b, img.height / b, {}};
    out.bytes.resize(size_t(out.width) * out.height * 3);
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x)
            for (int k = 0; k < 3; ++k) {
                double sum = 0;
                for (int j = 0; j < b; ++j)
                    for (int i = 0; i < b; ++i) sum += img.bytes[(size_t(y * b + j) * img.width + (x * b + i)) * 3 + k];
                out.bytes[(size_t(y) * out.width + x) * 3 + k] = uint8_t(std::lround(sum / (b * b)));
            }
    return out;
}

}  // namespace

// Whitted scenes at the file's own sample count: at least 30 dB against the reference.
class WhittedReference : public testing::TestWithParam<int> {};

TEST_P(WhittedReference, AtLeast30dB) {
    const Scene scene = load(GetParam());
    const double db = psnr(render(scene, scene.renderer.samples), reference(GetParam()));
    RecordProperty("psnr_db", std::to_string(db));
    EXPECT_GE(db, 30.0) << "scene " << GetParam();
}

INSTANTIATE_TEST_SUITE_P(Scenes, WhittedReference, testing::Values(1, 2, 7));

// Path-traced scenes at a few samples per pixel, compared on 8x8 block means (the
// full-sample comparison is the fidelity benchmark in docs/fidelity.md, too slow for CI).
// Parameters: scene, samples per pixel, minimum block PSNR (scene 5's caustics through glass
// stay noisy longest, hence more samples and a lower bar).
class PathTracedReference : public testing::TestWithParam<std::tuple<int, int, double>> {};

TEST_P(PathTracedReference, BlockMeansMatch) {
    const auto [n, spp, min_db] = GetParam();
    const Rgb8Image image = render(load(n), spp);
    const double db = psnr(block_average(image, 8), block_average(reference(n), 8));
    RecordProperty("block_psnr_db", std::to_string(db));
    EXPECT_GE(db, min_db) << "scene " << n;
}

INSTANTIATE_TEST_SUITE_P(Scenes, PathTracedReference,
                         testing::Values(std::make_tuple(3, 16, 30.0), std::make_tuple(4, 16, 30.0),
                                         std::make_tuple(5, 32, 26.0), std::make_tuple(6, 16, 30.0),
                                         std::make_tuple(8, 16, 30.0)));

// The references' pixel grid (docs/fidelity.md): scene 2 at its 8 spp scores 48 dB with it;
// with the grid half a pixel off in x and y (the earlier mapping) it scored 35 dB.
TEST(ReferenceSensitivity, PixelGridMatchesTheReferences) {
    const Scene scene = load(2);
    EXPECT_GE(psnr(render(scene, scene.renderer.samples), reference(2)), 45.0);
    // Pixel (i, j) sees the raster point (i - 1/2, j + 1/2) of the camera's unit square.
    const Vec2 centre = raster_to_camera(3.5, 5.5, 10, 20);
    EXPECT_DOUBLE_EQ(centre.x, 0.3);
    EXPECT_DOUBLE_EQ(centre.y, 0.3);
}

// The same tests fail under a wrong convention: a point light's power taken as flux
// (I = P / 4 pi) or a Lambertian BRDF of rho instead of rho / pi (light x pi).
TEST(ReferenceSensitivity, WrongConventionsFail) {
    const Rgb8Image ref = reference(2);
    for (double scale : {1.0 / (4 * kPi), kPi}) {
        Scene scene = load(2);
        for (Light& l : scene.lights) l.power = l.power * scale;
        EXPECT_LT(psnr(render(scene, 2), ref), 20.0) << "power scaled by " << scale;
    }
    // And an area light's power taken as flux instead of radiance (Le = P / (pi A)).
    Scene pt = load(3);
    for (Light& l : pt.lights) l.power = l.power / (kPi * 4 * kPi);
    EXPECT_LT(psnr(block_average(render(pt, 4), 8), block_average(reference(3), 8)), 20.0);
}
