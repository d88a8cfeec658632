// The flags `render` and `view` share (render/options.h): one table, read the same way by
// both commands (same ranges, same messages, same help) and applied by one function.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/args.h"
#include "render/options.h"
#include "scene/load.h"
#include "test_util.h"
#include "viewer/model.h"
#include "viewer/view_options.h"

namespace {

using namespace kr;

// The value texts a flag must accept and those it must refuse: each end of its range and
// just past it, or each of its names and one that is not.
struct FlagCases {
    std::vector<std::string> accepted, refused;
};

FlagCases cases_for(const SharedFlag& f) {
    FlagCases c;
    if (f.kind == FlagKind::name) {
        std::string names = f.range_text();  // "a | b | c"
        for (size_t at = 0; at <= names.size();) {
            size_t end = names.find(" | ", at);
            if (end == std::string::npos) end = names.size();
            c.accepted.push_back(names.substr(at, end - at));
            at = end + 3;
        }
        c.refused = {"bogus", ""};
        return c;
    }
    if (f.kind == FlagKind::integer) {
        const long long lo = (long long)f.lo, hi = (long long)f.hi;
        c.accepted = {std::to_string(lo), std::to_string(hi)};
        c.refused = {std::to_string(lo - 1), std::to_string(hi + 1), "1.5", "0x10"};
        return c;
    }
    c.accepted = {bound_text(f.hi)};
    c.refused = {bound_text(f.hi + (f.hi > 1 ? 1 : f.hi * 1e-6)), "nan"};
    if (f.lo_open) c.refused.push_back(bound_text(f.lo));
    else {
        c.accepted.push_back(bound_text(f.lo));
        c.refused.push_back(bound_text(f.lo > 0 ? f.lo / 2 : f.lo - 1));
    }
    return c;
}

// view's parse path, in-process: the UsageError message, or "" when accepted.
std::string view_parse(const std::string& flag, const std::string& text) {
    std::vector<std::string> args{"keithray", "view", flag, text};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    try {
        viewer::parse_view_options(int(argv.size()), argv.data());
    } catch (const UsageError& e) {
        return e.message;
    }
    return "";
}

class SharedFlags : public kr::test::ScratchDirTest {};

// Every entry's range ends are accepted and just past them refused, by both commands' parse
// paths (render and view on the command line, view's parser in-process), with one message.
TEST_F(SharedFlags, BothCommandsAcceptTheSameRanges) {
    ASSERT_GE(shared_flags().size(), 11u);
    for (const SharedFlag& f : shared_flags()) {
        const FlagCases c = cases_for(f);
        const std::string flag(f.name);
        for (const std::string& v : c.accepted) {
            SCOPED_TRACE(flag + " " + v);
            EXPECT_EQ(view_parse(flag, v), "");
            // --help after the flag: parsed, then the help printed (exit 0) instead of a run.
            for (const char* command : {"render", "view"}) {
                const auto r = cli(std::string(command) + " " + flag + " '" + v + "' --help");
                EXPECT_EQ(r.status, 0) << command << ": " << r.err;
            }
        }
        for (const std::string& v : c.refused) {
            SCOPED_TRACE(flag + " " + v);
            const std::string message = view_parse(flag, v);
            ASSERT_NE(message, "");
            // One line: the flag, what it expects (the range or the names) and the text quoted.
            EXPECT_EQ(message.rfind(flag + " expects ", 0), 0u) << message;
            const std::string expected = f.kind == FlagKind::name      ? "\"" + c.accepted.back() + "\""
                                         : f.kind == FlagKind::integer ? std::to_string((long long)f.hi)
                                                                       : bound_text(f.hi);
            EXPECT_NE(message.find(expected), std::string::npos) << message;
            EXPECT_NE(message.find(", got " + quote_user_text(v, 40)), std::string::npos) << message;
            for (const char* command : {"render", "view"}) {
                const auto r = cli(std::string(command) + " " + flag + " '" + v + "' --help");
                EXPECT_EQ(r.status, 2) << command;
                EXPECT_EQ(r.err.substr(0, r.err.find('\n')), "error: " + message) << command;
            }
        }
    }
}

// Both --help texts list the shared flags from the table, word for word.
TEST_F(SharedFlags, BothHelpTextsListTheTable) {
    const std::string table = shared_flags_help();
    EXPECT_NE(table.find("maximum ray depth, 0..20 (default"), std::string::npos) << table;
    EXPECT_NE(table.find("random seed, 0..4611686018427387904"), std::string::npos);
    EXPECT_NE(table.find("wrt | pt | pt-naive"), std::string::npos);
    for (const char* args : {"render --help", "view --help", "--help"}) {
        const auto r = cli(args);
        EXPECT_EQ(r.status, 0) << args;
        EXPECT_NE(r.out.find(table), std::string::npos) << args << "\n" << r.out;
    }
    EXPECT_EQ(viewer::view_usage().find(table) != std::string::npos, true);
}

// Every flag given: each setting takes the flag's value over the file's.
TEST(ApplyRenderOptions, FlagsOverTheFileAndUnsetKeepsIt) {
    Scene scene = load_scene_file(std::string(KEITHRAY_RES_DIR) + "/scenes/assignment_03.json").scene;
    Scene untouched = scene;
    const RenderSettings file = apply_render_options({}, untouched);
    EXPECT_EQ(untouched.display.tonemap, scene.display.tonemap);
    EXPECT_EQ(untouched.display.exposure, scene.display.exposure);
    EXPECT_EQ(file.target_spp, std::max(1, scene.renderer.samples));
    EXPECT_EQ(file.max_depth, scene.renderer.depth);
    EXPECT_EQ(file.seed, 0u);

    RenderOptions o;
    o.spp = 7;
    o.depth = 0;
    o.seed = 99;
    o.integrator = Integrator::pt_naive;
    o.estimator = Estimator::stratified;
    o.allocation = Allocation::uniform;
    o.light_sampling = LightSampling::area;
    o.tonemap = ToneMap::linear;
    o.exposure = -2.5;
    const RenderSettings s = apply_render_options(o, scene);
    EXPECT_EQ(s.target_spp, 7);
    EXPECT_EQ(s.max_depth, 0);
    EXPECT_EQ(s.seed, 99u);
    EXPECT_EQ(s.integrator, Integrator::pt_naive);
    EXPECT_EQ(s.estimator, Estimator::stratified);
    EXPECT_EQ(s.allocation, Allocation::uniform);
    EXPECT_EQ(s.light_sampling, LightSampling::area);
    EXPECT_EQ(scene.display.tonemap, ToneMap::linear);
    EXPECT_EQ(scene.display.exposure, -2.5);
}

// The viewer's settings after a load are what render applies to the same file and flags,
// parsed from the same command line.
TEST(ApplyRenderOptions, ViewerGetsWhatRenderGets) {
    std::vector<std::string> args{"keithray", "view", "--spp", "5", "--depth", "3", "--seed", "11",
                                  "--integrator", "wrt", "--estimator", "uniform", "--allocation", "uniform",
                                  "--light-sampling", "cone", "--tonemap", "linear", "--exposure", "1.25"};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    const viewer::ViewOptions view = viewer::parse_view_options(int(argv.size()), argv.data());

    const std::string file = std::string(KEITHRAY_RES_DIR) + "/scenes/assignment_03.json";
    Scene scene = load_scene_file(file).scene;
    const RenderSettings render = apply_render_options(view.render, scene);

    viewer::ViewerModel model;
    model.set_overrides(view.render);
    model.load(file);
    const RenderSettings& shown = model.settings().render;
    EXPECT_EQ(shown.target_spp, render.target_spp);
    EXPECT_EQ(shown.max_depth, render.max_depth);
    EXPECT_EQ(shown.seed, render.seed);
    EXPECT_EQ(shown.integrator, render.integrator);
    EXPECT_EQ(shown.estimator, render.estimator);
    EXPECT_EQ(shown.allocation, render.allocation);
    EXPECT_EQ(shown.light_sampling, render.light_sampling);
    EXPECT_EQ(shown.rr_depth, render.rr_depth);
    EXPECT_EQ(model.settings().tone.tonemap, scene.display.tonemap);
    EXPECT_EQ(model.settings().tone.exposure, scene.display.exposure);
    // And they are the flags' values, not the file's.
    EXPECT_EQ(render.target_spp, 5);
    EXPECT_EQ(render.seed, 11u);
    EXPECT_EQ(scene.display.exposure, 1.25);
}

}  // namespace
