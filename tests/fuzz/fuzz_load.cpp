// libFuzzer target for the scene loader (issue 6). The input bytes are a scene file's text.
// The contract under test (scene/load.h, render/render_scene.h): bad input ends in a
// kr::SceneError and nothing else; no crash, no sanitizer report, no other exception.
// A scene that loads must also:
//   - prepare (prepare_scene) or be refused with a SceneError,
//   - save to text that loads back and saves to the same text (scene/save.h's promise),
//   - render one tiny pass without a sanitizer report.
// Anything else escapes as an uncaught exception or a trap, which libFuzzer records as a crash.
//
// Build: cmake --preset asan (or fuzz) && cmake --build build-asan --target fuzz_load
// Run:   build-asan/tests/fuzz/fuzz_load -dict=tests/fuzz/scene.dict WORK_DIR tests/fuzz/corpus
#include <omp.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "render/progressive.h"
#include "render/render_scene.h"
#include "scene/load.h"
#include "scene/save.h"

namespace {

[[noreturn]] void fail(const char* what, const std::string& detail) {
    std::fprintf(stderr, "fuzz_load: %s\n%s\n", what, detail.c_str());
    std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    // One thread: the fuzzer runs one input at a time, and OpenMP teams only add noise.
    omp_set_num_threads(1);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    // A relative path, so the output path is resolved the way it is for a real file.
    const char* const file = "fuzz/scene.json";
    kr::LoadedScene loaded;
    try {
        loaded = kr::parse_scene(text, file);
    } catch (const kr::SceneError&) {
        return 0;  // the expected outcome for bad input
    }

    // Save -> load -> save is a fixed point. A SceneError here escapes: the saved text of a
    // loaded scene must always load.
    const std::string saved = kr::scene_to_json(loaded.scene);
    const kr::LoadedScene again = kr::parse_scene(saved, file);
    const std::string resaved = kr::scene_to_json(again.scene);
    if (resaved != saved) fail("save -> load -> save changed the text", saved + "\n---\n" + resaved);

    std::vector<std::string> warnings;
    kr::RenderScene scene;
    try {
        scene = kr::prepare_scene(loaded.scene, &warnings);
    } catch (const kr::SceneError&) {
        return 0;  // refused at the prepare stage (e.g. an active area light no primitive carries)
    }

    // One sample per pixel of a 3x2 image, whatever the file asks: exercises the camera,
    // the BVH and the integrators on hostile numbers without making the fuzzer slow.
    kr::RenderSettings settings = kr::RenderSettings::from_scene(scene.renderer);
    settings.target_spp = 1;
    if (settings.max_depth > 4) settings.max_depth = 4;
    kr::RenderState state(3, 2);
    kr::render_pass(scene, settings, state);
    (void)state.radiance();
    return 0;
}
