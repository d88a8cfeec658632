// Output and image files (issue 21): every output whole or untouched, all outputs of one
// render together, no temporary left behind (signals included), no device or read-only file
// replaced, and image readers that trust no header. One test per row of the "Output files"
// and "Image files read" tables in docs/robustness.md.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/file_write.h"
#include "core/image_formats.h"
#include "core/image_io.h"
#include "test_util.h"

namespace fs = std::filesystem;
using namespace kr;

namespace {

class Outputs : public test::ScratchDirTest {
protected:
    // A small valid scene whose output is `output` (JSON string text, escapes allowed).
    fs::path scene(const std::string& output = "out.ppm", const std::string& dims = "[16, 12]") {
        return write("scene.json", R"({
  "cameras": [{"id": "cam", "type": "pinhole", "fov": 45, "aspect": 1.333, "position": [0, 0, -5], "target": [0, 0, 0]}],
  "materials": [{"id": "white", "type": "diffuse", "rho": [0.8, 0.8, 0.8]}],
  "shapes": [{"id": "ball", "type": "sphere", "centre": [0, 0, 0], "radius": 1}],
  "lights": [{"id": "lamp", "type": "point", "position": [0, 3, -3], "power": [50, 50, 50]}],
  "scene": {"camera": "cam", "lights": ["lamp"],
    "primitives": [{"id": "ball", "type": "geometric", "shape": "ball", "material": "white"}],
    "renderer": {"type": "WRT", "dimensions": )" + dims + R"(, "samples": 1, "depth": 2, "output": ")" +
                                     output + R"("}}
})");
    }
    // Files of `folder` (recursively) whose name marks a temporary.
    std::vector<fs::path> temporaries(const fs::path& folder) const {
        std::vector<fs::path> found;
        std::error_code ec;
        for (auto it = fs::recursive_directory_iterator(folder, ec); it != fs::recursive_directory_iterator();
             it.increment(ec))
            if (it->path().filename().string().find(".tmp") != std::string::npos) found.push_back(it->path());
        return found;
    }
    static int lines(const std::string& text) { return int(std::count(text.begin(), text.end(), '\n')); }
};

const std::string kOld = "old output, not an image";

bool is_char_device(const fs::path& p) {
    struct stat st {};
    return ::lstat(p.c_str(), &st) == 0 && S_ISCHR(st.st_mode);
}

// A PNG signature and header chunk claiming width x height RGB pixels, and nothing else.
std::string png_header_only(uint32_t width, uint32_t height) {
    std::string s = "\x89PNG\r\n\x1a\n";
    s += std::string("\0\0\0\x0dIHDR", 8);
    for (uint32_t v : {width, height})
        for (int shift = 24; shift >= 0; shift -= 8) s += char((v >> shift) & 0xff);
    s += std::string("\x08\x02\0\0\0", 5);  // 8 bits, RGB, deflate, no filter, no interlace
    s += std::string("\0\0\0\0", 4);        // CRC (never reached)
    return s;
}

}  // namespace

// Issue 21.4: the depth map cannot be written (its name is a folder): nothing is, the old
// image stays, exit status 1, one line naming the depth file.
TEST_F(Outputs, DepthMapThatCannotBeWrittenLeavesTheOldImage) {
    const fs::path s = scene();
    write("x.ppm", kOld);
    fs::create_directories(dir / "x-depth.ppm");
    const test::CommandResult r = cli("render '" + s.string() + "' -q -o '" + (dir / "x.ppm").string() + "'");
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("x-depth.ppm\": is a folder"), std::string::npos) << r.err;
    EXPECT_EQ(test::read_file(dir / "x.ppm"), kOld);
    EXPECT_TRUE(temporaries(dir).empty());
}

// Issue 21.4: the image's name fits the file system, its depth map's ("-depth" added) does
// not: refused before anything is written.
TEST_F(Outputs, DepthMapNameTooLongLeavesTheOldImage) {
    const std::string stem(248, 'n');  // 252 bytes with .ppm; 258 with -depth
    const fs::path s = scene();
    write(stem + ".ppm", kOld);
    const test::CommandResult r = cli("render '" + s.string() + "' -q -o '" + (dir / (stem + ".ppm")).string() + "'");
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("258 bytes; this file system allows 255"), std::string::npos) << r.err;
    EXPECT_LT(r.err.size(), 600u) << "the name is quoted, bounded";
    EXPECT_EQ(test::read_file(dir / (stem + ".ppm")), kOld);
    EXPECT_TRUE(temporaries(dir).empty());
}

// Issue 21.6: a character device is refused, never replaced nor written through; so is
// /dev/full, which would otherwise "succeed".
TEST_F(Outputs, CharacterDeviceIsNeverReplaced) {
    fs::path device = "/dev/full";
    if (::mknod((dir / "dev.ppm").c_str(), S_IFCHR | 0666, makedev(1, 7)) == 0) device = dir / "dev.ppm";
    const fs::path s = scene();
    const test::CommandResult r = cli("render '" + s.string() + "' -q -o '" + device.string() + "'");
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("is a character device"), std::string::npos) << r.err;
    EXPECT_TRUE(is_char_device(device));
    EXPECT_FALSE(fs::exists(depth_path_for(device))) << "nothing written beside the device";
    EXPECT_TRUE(temporaries(dir).empty());
    // The library refuses /dev/null itself the same way.
    try {
        write_file_atomic("/dev/null", "x");
        ADD_FAILURE() << "/dev/null was accepted";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("\"/dev/null\": is a character device"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(is_char_device("/dev/null"));
}

// Issue 21.7: a NUL byte in "output" (JSON \u0000) is a load error naming the field, and
// nothing is written under the truncated name. The writer refuses such a path too.
TEST_F(Outputs, NulByteInOutputPathIsRefused) {
    const fs::path s = scene("a\\u0000b.ppm");
    const test::CommandResult r = cli("render '" + s.string() + "' -q");
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("/scene/renderer/output: expected a file path without NUL bytes"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "a"));
    EXPECT_FALSE(fs::exists(dir / "a-depth.ppm"));
    const fs::path nul = (dir / "c").string() + std::string(1, '\0') + "d.ppm";
    EXPECT_THROW(write_file_atomic(nul, "x"), std::runtime_error);
    EXPECT_FALSE(fs::exists(dir / "c"));
}

// Issue 21.8: a read-only output is refused (its mode says "keep this"); a writable one is
// replaced and keeps its permission bits.
TEST_F(Outputs, ReadOnlyOutputIsRefusedAndModesAreKept) {
    const fs::path s = scene();
    const fs::path out = write("x.ppm", kOld);
    fs::permissions(out, fs::perms::owner_read | fs::perms::group_read);
    const test::CommandResult r = cli("render '" + s.string() + "' -q -o '" + out.string() + "'");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("x.ppm\": is read-only"), std::string::npos) << r.err;
    EXPECT_EQ(test::read_file(out), kOld);
    EXPECT_EQ(fs::status(out).permissions(), fs::perms::owner_read | fs::perms::group_read);
    EXPECT_FALSE(fs::exists(dir / "x-depth.ppm"));

    const fs::perms kept = fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read;
    fs::permissions(out, kept);
    const test::CommandResult ok = cli("render '" + s.string() + "' -q -o '" + out.string() + "'");
    ASSERT_EQ(ok.status, 0) << ok.err;
    EXPECT_EQ(read_ppm(out).width, 16);
    EXPECT_EQ(fs::status(out).permissions(), kept);
}

// A write that fails part way (here the file size limit, with SIGXFSZ ignored so write()
// returns EFBIG, as on a full disk) is reported, removes its temporaries, keeps old files.
TEST_F(Outputs, FailedWriteIsReportedAndLeavesNothing) {
#ifdef KR_TEST_TSAN
    GTEST_SKIP() << "ThreadSanitizer's runtime cannot run under ulimit -f";
#endif
    const fs::path s = scene("out.ppm", "[64, 64]");
    write("out.ppm", kOld);
    const test::CommandResult r = test::run_command(
        std::string("sh -c \"trap '' XFSZ; ulimit -f 8; exec '") + KEITHRAY_EXE + "' render '" + s.string() + "' -q\"",
        dir);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("out.ppm\": cannot write: File too large"), std::string::npos) << r.err;
    EXPECT_EQ(test::read_file(dir / "out.ppm"), kOld);
    EXPECT_FALSE(fs::exists(dir / "out-depth.ppm"));
    EXPECT_TRUE(temporaries(dir).empty());
}

// Issue 21.5: SIGTERM or SIGINT while the outputs are being written leaves no temporary,
// and each output is either the old file or the new one, whole. The child is stopped the
// moment a temporary shows, so the signal lands inside the write window.
TEST_F(Outputs, SignalDuringWriteLeavesNoTemporary) {
    const int kSide = 1024;
    const fs::path s = scene("big.ppm", "[" + std::to_string(kSide) + ", " + std::to_string(kSide) + "]");
    int caught = 0;
    for (int sig : {SIGTERM, SIGINT}) {
        for (int attempt = 0; attempt < 6; ++attempt) {
            write("big.ppm", kOld);
            write("big-depth.ppm", kOld);
            const pid_t child = ::fork();
            ASSERT_GE(child, 0);
            if (child == 0) {
                const int null = ::open("/dev/null", O_WRONLY);
                ::dup2(null, 1);
                ::dup2(null, 2);
                ::signal(SIGINT, SIG_DFL);  // whatever the test runner's disposition
                ::signal(SIGTERM, SIG_DFL);
                ::execl(KEITHRAY_EXE, KEITHRAY_EXE, "render", s.c_str(), "-q", "--threads", "2", nullptr);
                ::_exit(127);
            }
            bool in_window = false;
            int status = 0;
            for (;;) {
                if (::waitpid(child, &status, WNOHANG) == child) break;
                if (!temporaries(dir).empty()) {
                    ::kill(child, SIGSTOP);
                    if (!temporaries(dir).empty()) {
                        in_window = true;
                        ::kill(child, sig);
                    }
                    ::kill(child, SIGCONT);
                    ASSERT_EQ(::waitpid(child, &status, 0), child);
                    break;
                }
            }
            EXPECT_TRUE(temporaries(dir).empty()) << strsignal(sig);
            for (const char* name : {"big.ppm", "big-depth.ppm"}) {
                const std::string text = test::read_file(dir / name);
                if (text == kOld) continue;
                const Rgb8Image image = read_ppm(dir / name);  // the new file, whole
                EXPECT_EQ(image.width, kSide);
                EXPECT_EQ(image.height, kSide);
            }
            if (in_window) {
                ++caught;
                EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << "status " << status;
                break;
            }
            EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "status " << status;
        }
    }
    EXPECT_GE(caught, 1) << "no attempt stopped the child inside its write window";
}

// The library's own cases: all-or-nothing across files, created folders removed again,
// symbolic links followed (the link stays), dangling links and duplicates refused.
TEST_F(Outputs, WriteFilesAtomicIsAllOrNothing) {
    write("a.txt", "old a");
    fs::create_directories(dir / "taken");
    EXPECT_THROW(write_files_atomic({{dir / "a.txt", "new a"}, {dir / "new" / "sub" / "b.txt", "b"}, {dir / "taken", "c"}}),
                 std::runtime_error);
    EXPECT_EQ(test::read_file(dir / "a.txt"), "old a");
    EXPECT_FALSE(fs::exists(dir / "new"));
    // A failure after the folders were made (the second temporary cannot be created in a
    // read-only folder; not as root, who may write there anyway) undoes them too.
    if (::geteuid() != 0) {
        fs::create_directories(dir / "locked");
        fs::permissions(dir / "locked", fs::perms::owner_read | fs::perms::owner_exec);
        EXPECT_THROW(write_files_atomic({{dir / "new" / "b.txt", "b"}, {dir / "locked" / "c.txt", "c"}}),
                     std::runtime_error);
        EXPECT_FALSE(fs::exists(dir / "new"));
    }
    write_files_atomic({{dir / "a.txt", "new a"}, {dir / "new" / "sub" / "b.txt", "b"}});
    EXPECT_EQ(test::read_file(dir / "a.txt"), "new a");
    EXPECT_EQ(test::read_file(dir / "new" / "sub" / "b.txt"), "b");

    write("real.txt", "real");
    fs::create_symlink("real.txt", dir / "link.txt");
    write_file_atomic(dir / "link.txt", "through the link");
    EXPECT_TRUE(fs::is_symlink(dir / "link.txt"));
    EXPECT_EQ(test::read_file(dir / "real.txt"), "through the link");
    fs::create_symlink("nowhere.txt", dir / "dangling.txt");
    EXPECT_THROW(write_file_atomic(dir / "dangling.txt", "x"), std::runtime_error);
    EXPECT_FALSE(fs::exists(dir / "nowhere.txt"));
    EXPECT_THROW(write_files_atomic({{dir / "a.txt", "1"}, {dir / "." / "a.txt", "2"}}), std::runtime_error);
    EXPECT_THROW(write_file_atomic("", "x"), std::runtime_error);
    EXPECT_TRUE(temporaries(dir).empty());
}

// Issue 21.10: a header's claims are checked against the limits and the file before memory
// is taken; 22 bytes claiming 20000x20000 pixels cost nothing and name the file.
TEST_F(Outputs, ImageHeadersAreCheckedAgainstTheFile) {
    auto message = [](const fs::path& p) -> std::string {
        try {
            read_image(p);
        } catch (const std::runtime_error& e) {
            return e.what();
        }
        return "(read)";
    };
    const fs::path huge = write("huge.ppm", "P6\n20000 20000\n255\nab");
    EXPECT_NE(message(huge).find("huge.ppm\": the header claims 20000x20000 pixels; images of 1 to 32768 pixels a "
                                 "side and at most 268435456 pixels are read"),
              std::string::npos)
        << message(huge);
    const fs::path lying = write("lying.ppm", "P6\n10000 10000\n255\nab");
    EXPECT_NE(message(lying).find("lying.ppm\": truncated: the header claims 10000x10000 pixels (300000000 bytes), "
                                  "the file holds 2"),
              std::string::npos)
        << message(lying);
    const fs::path wide = write("wide.ppm", "P6\n40000 1\n255\n");
    EXPECT_NE(message(wide).find("claims 40000x1 pixels; images of 1 to 32768"), std::string::npos) << message(wide);
    const fs::path big_number = write("number.ppm", "P6\n99999999999999999999 1\n255\n");
    EXPECT_NE(message(big_number).find("malformed PPM header: expected the width"), std::string::npos);
    const fs::path png = write("huge.png", png_header_only(16000, 16000));
    EXPECT_NE(message(png).find("huge.png\": truncated: the header claims 16000x16000 pixels, more than 33 bytes"),
              std::string::npos)
        << message(png);
    const fs::path short_png = write("short.png", png_header_only(4, 4));
    EXPECT_NE(message(short_png).find("short.png\": not a valid PNG image"), std::string::npos) << message(short_png);
    // A whole image still reads, by content.
    Rgb8Image small{3, 2, std::vector<uint8_t>(18, 7)};
    write_png(dir / "ok.png", small);
    write_ppm(dir / "ok.ppm", small);
    EXPECT_EQ(read_image(dir / "ok.png").bytes, small.bytes);
    EXPECT_EQ(read_image(dir / "ok.ppm").bytes, small.bytes);
    // A black image compresses as well as PNG can and still passes the ratio bound.
    Rgb8Image black{1024, 1024, std::vector<uint8_t>(1024 * 1024 * 3, 0)};
    write_png(dir / "black.png", black);
    EXPECT_EQ(read_image(dir / "black.png").bytes, black.bytes);
    const std::string whole = test::read_file(dir / "ok.ppm");
    write("cut.ppm", whole.substr(0, whole.size() - 1));
    EXPECT_NE(message(dir / "cut.ppm").find("truncated"), std::string::npos);
}

// Issue 21.11: psnr names both files when their sizes differ, refuses lying headers at
// once, and a result that cannot be written (stdout is /dev/full) is exit status 1.
TEST_F(Outputs, PsnrNamesFilesAndReportsAFailedOutput) {
    write_ppm(dir / "a.ppm", Rgb8Image{2, 2, std::vector<uint8_t>(12, 1)});
    write_ppm(dir / "b.ppm", Rgb8Image{3, 2, std::vector<uint8_t>(18, 1)});
    const std::string a = (dir / "a.ppm").string(), b = (dir / "b.ppm").string();
    const test::CommandResult sizes = cli("psnr '" + a + "' '" + b + "'");
    EXPECT_EQ(sizes.status, 1);
    EXPECT_EQ(lines(sizes.err), 1) << sizes.err;
    EXPECT_NE(sizes.err.find("a.ppm\" is 2x2 but \""), std::string::npos) << sizes.err;
    EXPECT_NE(sizes.err.find("b.ppm\" is 3x2"), std::string::npos) << sizes.err;

    write("huge.ppm", "P6\n20000 20000\n255\nab");
    const test::CommandResult huge = cli("psnr '" + (dir / "huge.ppm").string() + "' '" + a + "'");
    EXPECT_EQ(huge.status, 1);
    EXPECT_NE(huge.err.find("huge.ppm\": the header claims 20000x20000"), std::string::npos) << huge.err;

    const int full = test::run_command("test -w /dev/full", dir).status;
    if (full != 0) GTEST_SKIP() << "no writable /dev/full";
    const int psnr_status = std::system(
        (std::string("'") + KEITHRAY_EXE + "' psnr '" + a + "' '" + a + "' >/dev/full 2>'" + (dir / "err").string() + "'")
            .c_str());
    EXPECT_TRUE(WIFEXITED(psnr_status) && WEXITSTATUS(psnr_status) == 1) << psnr_status;
    EXPECT_NE(test::read_file(dir / "err").find("cannot write the results to standard output: No space left on device"),
              std::string::npos)
        << test::read_file(dir / "err");
    const fs::path s = scene();
    const int render_status = std::system((std::string("'") + KEITHRAY_EXE + "' render '" + s.string() +
                                           "' -q >/dev/full 2>/dev/null")
                                              .c_str());
    EXPECT_TRUE(WIFEXITED(render_status) && WEXITSTATUS(render_status) == 1) << render_status;
}

// The format table (core/image_formats.h): which format a name asks for, which files one
// output writes, and every format read back, whatever its name, as render writes it.
TEST_F(Outputs, FormatTableNamesEveryOutputAndReadsWhatRenderWrites) {
    EXPECT_EQ(output_format("a.PNG").format, ImageFormat::png);
    EXPECT_EQ(output_format("a.Exr").format, ImageFormat::exr);
    EXPECT_EQ(output_format("a.pfm").format, ImageFormat::pfm);
    EXPECT_EQ(output_format("a.jpg").format, ImageFormat::ppm);  // any other name: PPM
    EXPECT_EQ(output_format("a").format, ImageFormat::ppm);
    EXPECT_EQ(format_by_extension("a.jpg"), nullptr);
    EXPECT_EQ(output_file_paths("x/a.exr"), std::vector<fs::path>{"x/a.exr"});
    EXPECT_EQ(output_file_paths("x/a.pfm"), (std::vector<fs::path>{"x/a.pfm", "x/a-depth.pfm"}));
    EXPECT_EQ(output_file_paths("a"), (std::vector<fs::path>{"a", "a-depth.ppm"}));
    for (const ImageFormatInfo& f : kImageFormats) {
        EXPECT_EQ(&format_info(f.format), &f);
        EXPECT_EQ(format_by_extension(std::string("out") + f.extension), &f);
        EXPECT_EQ(f.depth_beside, f.format != ImageFormat::exr) << f.name;
        EXPECT_TRUE(f.layers & kLayerRadiance && f.layers & kLayerDepth) << f.name;
    }

    const fs::path s = scene();
    for (const ImageFormatInfo& f : kImageFormats) {
        const fs::path out = dir / (std::string("out") + f.extension);
        const test::CommandResult r = cli("render '" + s.string() + "' -q -o '" + out.string() + "'");
        ASSERT_EQ(r.status, 0) << r.err;
        for (const fs::path& file : output_file_paths(out)) {
            // Read by content: the same bytes under a name of no format read alike.
            const fs::path renamed = dir / "renamed.bin";
            fs::copy_file(file, renamed, fs::copy_options::overwrite_existing);
            const ImageFile image = read_image_file(renamed);
            EXPECT_EQ(image.hdr, f.hdr) << file;
            EXPECT_EQ(image.width(), 16) << file;
            EXPECT_EQ(image.height(), 12) << file;
        }
    }
    const ImageFile exr = read_image_file(dir / "out.exr");
    EXPECT_EQ(exr.radiance.albedo.size(), 3u * 16 * 12);
    EXPECT_EQ(exr.radiance.variance.size(), 3u * 16 * 12);
}
