// Whole runs of the command line against hostile files: inputs that are pipes or FIFOs (read
// once or refused, never opened twice), images too large for the memory left (said as
// such), the viewer's outputs that would replace its inputs, and help to a full device.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/types.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/image_hdr.h"
#include "core/image_io.h"
#include "robustness_util.h"
#include "test_util.h"

namespace fs = std::filesystem;
using namespace kr;

namespace {

class RobustRuns : public test::ScratchDirTest {
protected:
    // keithray run in the scratch folder under a time limit (a read that blocks fails the
    // test instead of hanging it).
    test::CommandResult here(const std::string& command) {
        return test::run_command("cd '" + dir.string() + "' && timeout 60 " + command, dir);
    }
    std::string exe() const { return std::string("'") + KEITHRAY_EXE + "'"; }
    void write_bytes(const std::string& name, const std::string& bytes) {
        std::ofstream(dir / name, std::ios::binary) << bytes;
    }
    fs::path scene_file() {
        const fs::path file = dir / "scene.json";
        std::ofstream(file) << robust::scene_json("out.ppm", "[8, 8]");
        return file;
    }
};

HdrImage grey_hdr(int width, int height) {
    HdrImage image;
    image.width = width;
    image.height = height;
    image.rgb.assign(image.pixel_count() * 3, 0.5f);
    return image;
}

}  // namespace

// A FIFO given as an image to psnr and compare is read once: an 8-bit image, a PFM and an
// EXR each give the figures of the same file read from disk.
TEST_F(RobustRuns, FifoImagesAreReadOnce) {
    write_bytes("a.ppm", encode_ppm(Rgb8Image{4, 3, std::vector<uint8_t>(36, 100)}));
    write_bytes("a.pfm", encode_pfm_rgb(grey_hdr(4, 3)));
    write_bytes("a.exr", encode_exr(grey_hdr(4, 3)));
    for (const std::string name : {"a.ppm", "a.pfm", "a.exr"}) {
        fs::remove(dir / "pipe");
        ASSERT_EQ(::mkfifo((dir / "pipe").c_str(), 0600), 0);
        const test::CommandResult r =
            here("sh -c \"cat " + name + " > pipe & " + exe() + " compare pipe " + name + " --max-rmse 0\"");
        EXPECT_EQ(r.status, 0) << name << "\n" << r.out << r.err;
    }
}

// The viewer re-reads and watches its scene: a FIFO (or a folder) as its scene or
// reference is refused at once, before anything would block on opening it.
TEST_F(RobustRuns, ViewerRefusesAFifoSceneOrReference) {
    ASSERT_EQ(::mkfifo((dir / "pipe").c_str(), 0600), 0);
    scene_file();
    const test::CommandResult scene = here(exe() + " view pipe --frames 1 --screenshot x.ppm");
    EXPECT_EQ(scene.status, 1);
    EXPECT_NE(scene.err.find("pipe\": the scene is a FIFO"), std::string::npos) << scene.err;
    const test::CommandResult reference = here(exe() + " view scene.json --reference pipe --frames 1 --screenshot x.ppm");
    EXPECT_EQ(reference.status, 1);
    EXPECT_NE(reference.err.find("--reference is a FIFO"), std::string::npos) << reference.err;
    EXPECT_FALSE(fs::exists(dir / "x.ppm"));
}

// No output of a viewer run replaces an input of it: the scene, the reference (a depth
// file beside a saved image included). Refused before anything is opened, exit 1.
TEST_F(RobustRuns, ViewerOutputsNeverReplaceItsInputs) {
    scene_file();
    write_bytes("ref.ppm", "reference");
    write_bytes("ref-depth.ppm", "reference depth");
    const std::string before = test::read_file(dir / "scene.json");
    for (const std::string flags :
         {"--frames 1 --screenshot scene.json", "--frames 1 --window-shot ./scene.json", "--status-file scene.json",
          "--reference ref.ppm --frames 1 --stats-json ref.ppm", "--reference ref-depth.ppm --save-image ref.ppm",
          "--reference ref.ppm --save-scene sub/../ref.ppm"}) {
        const test::CommandResult r = here(exe() + " view scene.json " + flags);
        EXPECT_EQ(r.status, 1) << flags;
        EXPECT_NE(r.err.find("would overwrite"), std::string::npos) << flags << "\n" << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    }
    EXPECT_EQ(test::read_file(dir / "scene.json"), before);
    EXPECT_EQ(test::read_file(dir / "ref.ppm"), "reference");
    EXPECT_EQ(test::read_file(dir / "ref-depth.ppm"), "reference depth");
}

// Viewer flags that would mean nothing are refused before a window opens or a file is
// written, with one error line naming the flag: a pixel outside the image (exit 1, once the
// scene's size is known), a drag without a selection or an empty region (bad usage, exit 2),
// two outputs naming one file (exit 1).
TEST_F(RobustRuns, ViewerFlagsThatMeanNothingAreRefused) {
    scene_file();  // 8x8 pixels
    const std::pair<std::string, std::string> cases[] = {
        {"--frames 1 --select 100,2 --move-selection 3,3", "--select 100,2 is outside the 8x8 image"},
        {"--frames 1 --click-focus 4,8", "--click-focus 4,8 is outside the 8x8 image"},
        {"--frames 1 --region 0,0 9,8", "--region 0,0 9,8 reaches outside the 8x8 image"},
        {"--frames 1 --region 20,20 30,30", "--region 20,20 30,30 reaches outside"},
        {"--frames 1 --move-selection 3,3", "--move-selection drags the selection"},
        {"--frames 1 --region 4,4 4,8", "an empty region"},
        {"--frames 1 --region 6,6 2,2", "an empty region"},
        {"--frames 1 --screenshot same.ppm --save-image same.ppm", "--screenshot \"same.ppm\" and --save-image \"same.ppm\""},
        {"--frames 1 --save-image out.ppm --save-scene out.ppm", "are one file"},
        {"--frames 1 --save-image out.ppm --screenshot out-depth.ppm", "--save-image's depth file \"out-depth.ppm\""},
    };
    for (const auto& [flags, message] : cases) {
        const test::CommandResult r = here(exe() + " view scene.json --save-image out.ppm " + flags);
        const bool usage = message.find("drags") != std::string::npos || message.find("empty") != std::string::npos;
        EXPECT_EQ(r.status, usage ? 2 : 1) << flags << "\n" << r.err;
        EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
        EXPECT_NE(r.err.substr(0, r.err.find('\n')).find(message), std::string::npos) << flags << "\n" << r.err;
        // One error line (bad usage adds the pointer to --help).
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), usage ? 2 : 1) << r.err;
        EXPECT_EQ(r.err.find("window GL"), std::string::npos) << "a window opened: " << r.err;
        for (const char* name : {"out.ppm", "out-depth.ppm", "same.ppm", "same-depth.ppm"})
            EXPECT_FALSE(fs::exists(dir / name)) << flags << ": " << name;
    }
}

// A viewer image named for a format it does not write is refused before the window opens:
// a .jpg anywhere, and an HDR name for the 8-bit shots (a PPM's bytes under out.exr before).
TEST_F(RobustRuns, ViewerImageNamesMatchWhatIsWritten) {
    scene_file();
    for (const std::string flags : {"--frames 1 --screenshot shot.jpg", "--frames 1 --screenshot shot.exr",
                                    "--frames 1 --window-shot shot.PFM"}) {
        const test::CommandResult r = here(exe() + " view scene.json " + flags);
        EXPECT_EQ(r.status, 1) << flags;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_NE(r.err.find(flags.substr(flags.rfind(' ') + 1)), std::string::npos) << r.err;
    }
    for (const char* name : {"shot.jpg", "shot.exr", "shot.PFM"}) EXPECT_FALSE(fs::exists(dir / name)) << name;
}

// Help to a full device fails like any other output to it.
TEST_F(RobustRuns, HelpToAFullDeviceFails) {
    for (const char* command : {"--help", "render --help", "view --help"}) {
        const test::CommandResult r = here("sh -c \"" + exe() + " " + command + " > /dev/full\"");
        EXPECT_EQ(r.status, 1) << command;
        EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << command << r.err;
    }
}

// An image too large for the memory the process may take is "not enough memory for FILE",
// whatever its format, never "not a readable image" or an abort. The address space is
// limited (ulimit -v) to what the process needs plus far less than the image.
TEST_F(RobustRuns, ImageTooLargeForMemorySaysSo) {
#ifdef KR_TEST_SANITIZED
    GTEST_SKIP() << "the sanitizers' runtimes reserve address space beyond any ulimit -v";
#endif
    const int side = 4096;  // 16.8 M pixels: 201 MB of RGB floats
    write_bytes("big.pfm", encode_pfm_rgb(grey_hdr(side, side)));
    write_bytes("big.exr", encode_exr(grey_hdr(side, side)));
    write_bytes("big.ppm", encode_ppm(Rgb8Image{side, side, std::vector<uint8_t>(size_t(side) * side * 3, 7)}));
    write_bytes("small.ppm", encode_ppm(Rgb8Image{4, 4, std::vector<uint8_t>(48, 7)}));
    // The smallest limit (in steps of 32 MiB) under which psnr of two small images runs.
    long base_kib = 0;
    for (long kib = 64 * 1024; kib <= 4096 * 1024 && !base_kib; kib += 32 * 1024)
        if (here("sh -c \"ulimit -v " + std::to_string(kib) + "; exec " + exe() + " psnr small.ppm small.ppm\"").status == 0)
            base_kib = kib;
    ASSERT_GT(base_kib, 0);
    const std::string limit = std::to_string(base_kib + 64 * 1024);  // 64 MiB more: a third of the image
    for (const char* name : {"big.pfm", "big.exr", "big.ppm"}) {
        const test::CommandResult r =
            here("sh -c \"ulimit -v " + limit + "; exec " + exe() + " psnr " + name + " " + name + "\"");
        EXPECT_EQ(r.status, 1) << name << "\n" << r.out << r.err;
        EXPECT_NE(r.err.find("not enough memory for"), std::string::npos) << name << "\n" << r.err;
        EXPECT_EQ(r.err.find("readable"), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    }
}
