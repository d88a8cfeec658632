// Out of memory at every step of a command: each command runs under a sweep of address-space
// limits (ulimit -v), from the least under which the program starts to the least under which
// the command succeeds, so that the allocation that fails moves through every stage (the
// scene's JSON, its DOM and the loaded scene, the prepared scene and its BVH, the render
// state, the passes, the denoiser, the output images and their encoding). Every run either
// succeeds with whole outputs, or exits 1 with one line naming the file and saying "not
// enough memory", nothing written: never a signal (std::terminate's abort), never a C++ name
// (std::bad_alloc), never a temporary left behind.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "core/image_formats.h"
#include "core/image_hdr.h"
#include "core/rng.h"
#include "test_util.h"

namespace fs = std::filesystem;
using namespace kr;

namespace {

// `count` random spheres in a cube of side 60, every other one an area light of its own (the
// loader's and prepare_scene's worst case), rendered at 40x40 pixels, 2 spp.
std::string many_spheres_json(int count) {
    std::string shapes, lights, light_ids, prims;
    Rng rng(1, 2);
    for (int i = 0; i < count; ++i) {
        const std::string id = std::to_string(i), sep = i ? "," : "";
        char buf[160];
        std::snprintf(buf, sizeof buf, R"({"id": "s%d", "type": "sphere", "centre": [%.4f, %.4f, %.4f], "radius": %.4f})",
                      i, 60 * rng.next() - 30, 60 * rng.next() - 30, 60 * rng.next() - 30, 0.5 + 1.5 * rng.next());
        shapes += sep + buf;
        if (i % 2 == 0) {
            lights += sep + R"({"id": "l)" + id + R"(", "type": "area", "shape": "s)" + id + R"(", "power": [1, 1, 1]})";
            light_ids += sep + "\"l" + id + "\"";
            prims += sep + R"({"id": "p)" + id + R"(", "type": "emissive", "shape": "s)" + id +
                     R"(", "material": "e", "light": "l)" + id + "\"}";
        } else {
            prims += sep + R"({"id": "p)" + id + R"(", "type": "geometric", "shape": "s)" + id + R"(", "material": "m"})";
        }
    }
    return R"({"cameras": [{"id": "cam", "type": "pinhole", "fov": 60, "aspect": 1, "position": [0, 0, -80], "target": [0, 0, 0]}],
"materials": [{"id": "m", "type": "diffuse", "rho": [0.7, 0.7, 0.7]}, {"id": "e", "type": "diffuse", "rho": [0, 0, 0]}],
"shapes": [)" + shapes + "],\n\"lights\": [" + lights + "],\n\"scene\": {\"camera\": \"cam\", \"lights\": [" + light_ids +
           "], \"primitives\": [" + prims +
           "],\n\"renderer\": {\"type\": \"PT\", \"dimensions\": [40, 40], \"samples\": 2, \"depth\": 3, \"output\": \"out.ppm\"}}}";
}

HdrImage grey_hdr(int width, int height, float value) {
    HdrImage image;
    image.width = width;
    image.height = height;
    image.rgb.assign(image.pixel_count() * 3, value);
    return image;
}

class RobustMemory : public test::ScratchDirTest {
protected:
    void SetUp() override {
        test::ScratchDirTest::SetUp();
#ifdef KR_TEST_SANITIZED
        GTEST_SKIP() << "the sanitizers' runtimes reserve address space beyond any ulimit -v";
#endif
    }

    // keithray `args` in the scratch folder under an address-space limit of `kib` KiB.
    test::CommandResult under(long kib, const std::string& args) {
        return test::run_command("cd '" + dir.string() + "' && ulimit -v " + std::to_string(kib) + " && exec '" +
                                     KEITHRAY_EXE + "' " + args,
                                 dir);
    }

    // The least limit, in steps of `step` KiB between `lo` (fails) and `hi` (succeeds), under
    // which `args` succeeds (a bisection: success only grows with the limit).
    long least_limit(const std::string& args, long lo, long hi, long step) {
        if (under(hi, args).status != 0) return -1;
        while (hi - lo > step) {
            const long mid = lo + (hi - lo) / 2;
            (under(mid, args).status == 0 ? hi : lo) = mid;
        }
        return hi;
    }

    // The files of the scratch folder, less the captured output.
    std::vector<std::string> files() const {
        std::vector<std::string> out;
        for (const auto& e : fs::directory_iterator(dir)) {
            const std::string name = e.path().filename().string();
            if (name != "stdout" && name != "stderr") out.push_back(name);
        }
        std::sort(out.begin(), out.end());
        return out;
    }

    // Runs `args` under `points` limits from the least under which the program starts to the
    // least under which `args` succeeds, and checks every run: `outputs` (removed before each
    // run) are whole after a success (`whole`) and absent after a failure, whose one line names
    // one of `names` and says "not enough memory".
    void sweep(const std::string& args, const std::vector<std::string>& outputs, const std::vector<std::string>& names,
               const std::function<void(const std::string&)>& whole, int points) {
        static const long start = least_limit("--help", 4 * 1024, 4096 * 1024, 4 * 1024);  // once per process
        const long enough = least_limit(args, start, start + 2048 * 1024, 16 * 1024);
        ASSERT_GT(start, 0);
        ASSERT_GT(enough, start) << args;
        const std::vector<std::string> before = [&] {
            for (const std::string& o : outputs) fs::remove(dir / o);
            return files();
        }();
        int failures = 0;
        for (int k = 0; k <= points; ++k) {
            const long kib = start + (enough - start) * k / points;
            for (const std::string& o : outputs) fs::remove(dir / o);
            const test::CommandResult r = under(kib, args);
            const std::string where = args + " under ulimit -v " + std::to_string(kib) + "\n" + r.err;
            ASSERT_TRUE(r.status == 0 || r.status == 1) << "status " << r.status << ": " << where;
            EXPECT_EQ(r.err.find("std::"), std::string::npos) << where;
            EXPECT_EQ(r.err.find("bad_alloc"), std::string::npos) << where;
            EXPECT_EQ(r.err.find("terminate"), std::string::npos) << where;
            if (r.status == 0) {
                for (const std::string& o : outputs) whole(o);
            } else {
                ++failures;
                EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << where;
                EXPECT_NE(r.err.find("not enough memory"), std::string::npos) << where;
                EXPECT_TRUE(std::any_of(names.begin(), names.end(),
                                        [&](const std::string& n) { return r.err.find(n) != std::string::npos; }))
                    << where;
                EXPECT_EQ(files(), before) << where;  // nothing written, no temporary left
            }
            for (const std::string& f : files()) EXPECT_EQ(f.find(".tmp"), std::string::npos) << f << ": " << where;
        }
        EXPECT_GE(failures, points - 1) << args;  // the points below `enough` fail, each somewhere else
        std::printf("%s: starts under %ld KiB, succeeds under %ld KiB; %d of %d runs between failed\n", args.c_str(),
                    start, enough, failures, points + 1);
    }

    void expect_image(const std::string& name) {
        const ImageFile image = read_image_file(dir / name);
        EXPECT_EQ(image.width(), 40) << name;
    }
};

}  // namespace

// A scene of 5,000 spheres (2,500 of them lights): the threads' stacks, the loader's DOM and
// scene, the BVH (Embree's threads), the render state, the passes, the final denoiser and the
// EXR, in turn, run out of memory. (A growing ordered_map copied the DOM's arrays, and a
// copy that failed aborted the process: nlohmann's destructor allocates.)
TEST_F(RobustMemory, RenderOfManySpheresAtEveryLimit) {
    std::ofstream(dir / "many.json") << many_spheres_json(5000);
    sweep("render many.json -q --denoise -o out.exr", {"out.exr"}, {"many.json"},
          [&](const std::string& name) { expect_image(name); }, 8);
}

// psnr and compare of two 1024x1024 images: the threads, reading either, the figures, the
// difference picture.
TEST_F(RobustMemory, PsnrAndCompareOfLargeImagesAtEveryLimit) {
    std::ofstream(dir / "a.exr", std::ios::binary) << encode_exr(grey_hdr(1024, 1024, 0.5f));
    std::ofstream(dir / "b.pfm", std::ios::binary) << encode_pfm_rgb(grey_hdr(1024, 1024, 0.25f));
    sweep("psnr a.exr b.pfm", {}, {"a.exr", "b.pfm"}, [](const std::string&) {}, 5);
    sweep("compare a.exr b.pfm --max-rmse 1 --diff d.png", {"d.png"}, {"a.exr", "b.pfm", "d.png"},
          [&](const std::string& name) { EXPECT_EQ(read_image_file(dir / name).width(), 1024); }, 5);
}

// A render resumed from its checkpoint (a 200x200 image: 4 MB of state): reading and decoding
// the checkpoint, the state, the image. The message names the scene or the checkpoint.
TEST_F(RobustMemory, ResumeFromACheckpointAtEveryLimit) {
    std::string scene = many_spheres_json(200);
    scene.replace(scene.find("[40, 40]"), 8, "[200, 200]");
    std::ofstream(dir / "scene.json") << scene;
    ASSERT_EQ(under(8192 * 1024, "render scene.json -q --spp 2 --checkpoint c.ckpt --every 0 -o first.png").status, 0);
    fs::remove(dir / "first.png");
    sweep("render scene.json -q --spp 2 --resume c.ckpt -o out.png", {"out.png"}, {"scene.json", "c.ckpt"},
          [&](const std::string& name) { EXPECT_EQ(read_image_file(dir / name).width(), 200); }, 6);
}
