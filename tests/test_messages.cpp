// Hostile user text and sizes (issue 21): every error or warning is one bounded line with
// user text quoted and escaped; scene files have a size limit; memory the render cannot have
// is refused up front; every numeric flag states its range.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "core/limits.h"
#include "core/memory.h"
#include "core/text.h"
#include "render/outputs.h"
#include "render/progressive.h"
#include "scene/load.h"
#include "test_util.h"

using namespace kr;
namespace fs = std::filesystem;

namespace {

// A message fit for a terminal: one line, no escape character, bounded.
void expect_one_bounded_line(const std::string& message, size_t max_bytes = 600) {
    EXPECT_EQ(message.find('\n'), std::string::npos) << message.substr(0, 2000);
    EXPECT_EQ(message.find('\r'), std::string::npos) << message.substr(0, 2000);
    EXPECT_EQ(message.find('\x1b'), std::string::npos) << message.substr(0, 2000);
    EXPECT_LE(message.size(), max_bytes) << message.substr(0, 2000);
}

std::string load_error(const std::string& json) {
    try {
        parse_scene(json, "hostile.json");
    } catch (const SceneError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no error";
    return "";
}

const std::string kScene = R"({
  "cameras": [{"id": "cam", "type": "pinhole", "fov": 45, "aspect": 1, "position": [0, 0, -5], "target": [0, 0, 0]}],
  "materials": [{"id": "white", "type": "diffuse", "rho": [0.8, 0.8, 0.8]}],
  "shapes": [{"id": "ball", "type": "sphere", "centre": [0, 0, 0], "radius": 1}],
  "lights": [{"id": "lamp", "type": "point", "position": [0, 3, -3], "power": [50, 50, 50]}],
  "scene": {"camera": "cam", "lights": ["lamp"],
            "primitives": [{"id": "ball", "type": "geometric", "shape": "ball", "material": "white"}],
            "renderer": {"type": "WRT", "dimensions": [DIMS], "samples": 1, "depth": 2, "output": "out.ppm"}}
})";

std::string scene_with(const std::string& dims) {
    std::string s = kScene;
    s.replace(s.find("DIMS"), 4, dims);
    return s;
}

class Hostile : public test::ScratchDirTest {};

// Lines of a program's stderr that start with "error:".
int error_lines(const std::string& err) {
    int n = 0;
    for (size_t at = 0; at < err.size();) {
        if (err.compare(at, 6, "error:") == 0) ++n;
        const size_t next = err.find('\n', at);
        if (next == std::string::npos) break;
        at = next + 1;
    }
    return n;
}

}  // namespace

// ---- the helper itself

TEST(QuoteUserText, EscapesControlCharactersQuotesAndBadUtf8) {
    EXPECT_EQ(quote_user_text("plain key"), "\"plain key\"");
    EXPECT_EQ(quote_user_text("a\nb\r\tc"), "\"a\\nb\\r\\tc\"");
    EXPECT_EQ(quote_user_text("\x1b[31mred"), "\"\\x1B[31mred\"");
    EXPECT_EQ(quote_user_text("say \"hi\" \\"), "\"say \\\"hi\\\" \\\\\"");
    EXPECT_EQ(quote_user_text(std::string("nul\0x", 5)), "\"nul\\x00x\"");
    EXPECT_EQ(quote_user_text("\xff\xfe"), "\"\\xFF\\xFE\"");
    EXPECT_EQ(quote_user_text("\xc2\x9b" "2J"), "\"\\u009B2J\"");  // C1 CSI
    EXPECT_EQ(quote_user_text("caf\xc3\xa9 \xe2\x9c\x93"), "\"caf\xc3\xa9 \xe2\x9c\x93\"");  // UTF-8 kept
    EXPECT_EQ(quote_user_text("\xed\xa0\x80"), "\"\\xED\\xA0\\x80\"");  // a surrogate is not UTF-8
    EXPECT_EQ(quote_user_text("\xc0\xaf"), "\"\\xC0\\xAF\"");          // nor an overlong '/'
}

TEST(QuoteUserText, CutsLongTextWithAnEllipsisAndItsLength) {
    const std::string key(1 << 20, 'k');
    const std::string q = quote_user_text(key);
    EXPECT_EQ(q, "\"" + std::string(kQuotedTextBytes, 'k') + "\"... (1048576 bytes)");
    // Never inside a UTF-8 character: 3 bytes of "é" (2 each) fit in 4.
    EXPECT_EQ(quote_user_text("\xc3\xa9\xc3\xa9\xc3\xa9", 5), "\"\xc3\xa9\xc3\xa9\"... (6 bytes)");
    EXPECT_EQ(quote_user_text("abc", 3), "\"abc\"");
}

TEST(QuoteUserText, ShowKeepsPlainTextAndQuotesTheRest) {
    EXPECT_EQ(show_user_text("res/scenes/a b.json"), "res/scenes/a b.json");
    EXPECT_EQ(show_user_text("a\nb.json"), "\"a\\nb.json\"");
    EXPECT_EQ(show_user_text(std::string(500, 'x'), 10), "\"xxxxxxxxxx\"... (500 bytes)");
    EXPECT_EQ(show_user_text(""), "\"\"");
}

// ---- the loader's messages

TEST(HostileText, KeyWithANewlineOrEscapesStaysOneLine) {
    // As JSON literals; the last is not UTF-8, which the parser refuses with the bytes it read.
    for (const std::string key : {"\"bad\\nerror: forged\"", "\"\\u001b]0;title\\u0007\\u001b[2J\"", "\"\xff\xfe\\r\""}) {
        std::string json = scene_with("2, 2");
        json.replace(json.find("\"cameras\""), 9, key + ": 1, \"cameras\"");
        const std::string e = load_error(json);
        expect_one_bounded_line(e);
        EXPECT_TRUE(e.find("unknown key") != std::string::npos || e.find("malformed JSON") != std::string::npos) << e;
    }
}

TEST(HostileText, MegabyteKeyGivesABoundedLine) {
    std::string json = scene_with("2, 2");
    json.replace(json.find("\"fov\""), 5, "\"" + std::string(1 << 20, 'f') + "\": 1, \"fov\"");
    const std::string e = load_error(json);
    expect_one_bounded_line(e);
    EXPECT_NE(e.find("(1048576 bytes)"), std::string::npos) << e.substr(0, 600);
}

TEST(HostileText, MillionDigitNumbersGiveABoundedLine) {
    const std::string digits(1000000, '9');
    std::string json = scene_with("2, 2");
    // Overflows to infinity: "not a finite number".
    json.replace(json.find("\"fov\": 45"), 9, "\"fov\": " + digits);
    std::string e = load_error(json);
    expect_one_bounded_line(e);
    EXPECT_NE(e.find("not a finite number"), std::string::npos) << e;
    EXPECT_NE(e.find("/cameras/0/fov"), std::string::npos) << e;
    // Followed by garbage: a syntax error whose "last read" excerpt is that token.
    json = scene_with("2, 2");
    json.replace(json.find("\"fov\": 45"), 9, "\"fov\": 1" + digits + "e");
    e = load_error(json);
    expect_one_bounded_line(e);
    EXPECT_NE(e.find("malformed JSON"), std::string::npos) << e;
    // A million digits of a fraction is a fine number, reported by its value.
    json = scene_with("2, 2");
    json.replace(json.find("\"fov\": 45"), 9, "\"fov\": 0." + digits);
    json.replace(json.find("\"aspect\": 1"), 11, "\"aspect\": -0." + digits);
    e = load_error(json);
    expect_one_bounded_line(e);
    EXPECT_NE(e.find("got -1"), std::string::npos) << e;
}

TEST(HostileText, IdCannotForgeAnErrorLine) {
    const std::string id = "lamp\nerror: forged\x1b[0m";
    std::string json = scene_with("2, 2");
    // An id in an error: a dangling reference.
    json.replace(json.find("\"lights\": [\"lamp\"]"), 18, "\"lights\": [" + nlohmann::json(id).dump() + "]");
    std::string e = load_error(json);
    expect_one_bounded_line(e);
    EXPECT_NE(e.find("lamp\\nerror: forged\\x1B[0m"), std::string::npos) << e;
    // An id in a warning: an area light whose primitive emits from another shape.
    json = R"({
      "cameras": [{"id": "cam", "type": "pinhole", "fov": 45, "aspect": 1, "position": [0, 0, -5], "target": [0, 0, 0]}],
      "materials": [{"id": "white", "type": "diffuse", "rho": [0.8, 0.8, 0.8]}],
      "shapes": [{"id": "ball", "type": "sphere", "centre": [0, 0, 0], "radius": 1},
                 {"id": "other", "type": "sphere", "centre": [0, 3, 0], "radius": 1}],
      "lights": [{"id": ID, "type": "area", "shape": "other", "power": [1, 1, 1]}],
      "scene": {"camera": "cam", "lights": [ID],
                "primitives": [{"id": "ball", "type": "emissive", "shape": "ball", "material": "white", "light": ID}],
                "renderer": {"type": "PT", "dimensions": [2, 2], "samples": 1, "depth": 2, "output": "out.ppm"}}})";
    for (size_t at; (at = json.find("ID")) != std::string::npos;) json.replace(at, 2, nlohmann::json(id).dump());
    std::vector<std::string> warnings;
    prepare_scene(parse_scene(json, "w.json").scene, &warnings);
    ASSERT_EQ(warnings.size(), 1u);
    expect_one_bounded_line(warnings[0]);
    EXPECT_NE(warnings[0].find("\"lamp\\nerror: forged\\x1B[0m\""), std::string::npos) << warnings[0];
}

TEST_F(Hostile, CliPrintsOneLinePerMessage) {
    // A scene file whose name holds a newline and an escape sequence, with a forged id.
    const std::string name = "sc\nerror: forged\x1b[2J.json";
    std::string json = scene_with("2, 2");
    json.replace(json.find("\"lights\": [\"lamp\"]"), 18, "\"lights\": [\"x\\nerror: forged\"]");
    write(name, json);
    test::CommandResult r = cli("render \"$(printf 'sc\\nerror: forged\\033[2J.json')\" -q");
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(error_lines(r.err), 1) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("\"sc\\nerror: forged\\x1B[2J.json\""), std::string::npos) << r.err;
    // Flags: an unknown one, and a bad value, each one line of usage error.
    for (const std::string args : {"render \"$(printf -- '--x\\nerror: y')\"", "render --spp \"$(printf '1\\033[2J')\"",
                                   "render --spp \"$(head -c 100000 /dev/zero | tr '\\0' 7)\""}) {
        r = cli(args);
        EXPECT_EQ(r.status, 2) << args;
        const std::string first = r.err.substr(0, r.err.find('\n'));
        expect_one_bounded_line(first, 200);
        EXPECT_EQ(error_lines(r.err), 1) << r.err;
        EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r.err;
    }
}

// ---- flags: ranges stated

TEST_F(Hostile, EveryNumericFlagStatesItsRange) {
    const fs::path scene = write("s.json", scene_with("2, 2"));
    const std::string s = "render '" + scene.string() + "' -q ";
    const std::pair<std::string, std::string> cases[] = {
        {"--time 1e9", "--time expects a number in (0, 1000000], got \"1e9\""},
        {"--time 0", "--time expects a number in (0, 1000000]"},
        {"--noise 1e-12", "--noise expects a number in [0.0001, 1], got \"1e-12\""},
        {"--noise 2", "--noise expects a number in [0.0001, 1]"},
        {"--spp 0", "--spp expects an integer in [1, 16777216]"},
        {"--spp 16777217", "--spp expects an integer in [1, 16777216]"},
        {"--depth 21", "--depth expects an integer in [0, 20]"},
        {"--depth -1", "--depth expects an integer in [0, 20]"},
        {"--threads 0", "--threads expects an integer in [1, 4096]"},
        {"--blur 4097", "--blur expects an integer in [0, 4096]"},
        {"--seed -1", "--seed expects an integer in [0, 4611686018427387904]"},
        {"--seed 0x10", "--seed expects an integer"},
        {"--time nan", "--time expects a number in (0, 1000000]"},
        {"--time ' 5'", "--time expects a number"},
    };
    for (const auto& [flags, expected] : cases) {
        const test::CommandResult r = cli(s + flags);
        EXPECT_EQ(r.status, 2) << flags << ": " << r.err;
        EXPECT_NE(r.err.find("error: " + expected), std::string::npos) << flags << ": " << r.err;
    }
    EXPECT_EQ(cli(s + "--time 1e6 --spp 1").status, 0);
    EXPECT_EQ(cli(s + "--depth 20 --blur 4096 --seed 4611686018427387904").status, 0);
}

// --noise without --spp ends even when the target is out of reach: one noisy pixel keeps an
// error of the order of 1/256 of one pass's after 65536 passes, far above 1e-4.
TEST_F(Hostile, NoiseWithoutSppStopsAtThePassCap) {
    std::string json = scene_with("1, 1");
    // A ball filling the view, lit from the camera: its shading varies across the pixel.
    json.replace(json.find("\"position\": [0, 3, -3]"), 22, "\"position\": [0, 0, -5]");
    json.replace(json.find("\"radius\": 1"), 11, "\"radius\": 4.5");
    const fs::path scene = write("one.json", json);
    const test::CommandResult r = cli("render '" + scene.string() + "' -q --threads 1 --noise 0.0001");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("stopped by the cap of " + std::to_string(kMaxOpenEndedPasses) + " passes (no --spp) after " +
                         std::to_string(kMaxOpenEndedPasses) + " passes"),
              std::string::npos)
        << r.err;
}

// ---- memory and sizes

TEST_F(Hostile, SceneFileSizeIsBounded) {
    // /dev/zero: a bounded read, refused at the limit (without it, ~1 GB was read first).
    test::CommandResult r = cli("render /dev/zero -q");
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("error: /dev/zero: scene file longer than 67108864 bytes (64.0 MiB)"), std::string::npos)
        << r.err;
    expect_one_bounded_line(r.err.substr(0, r.err.size() - 1));
    // A regular file above the limit is refused by its size, before reading (a sparse file).
    const fs::path big = dir / "big.json";
    std::ofstream(big) << "{}";
    fs::resize_file(big, kMaxSceneFileBytes + 1);
    try {
        load_scene_file(big);
        ADD_FAILURE() << "no error";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("scene file of 67108865 bytes; expected at most 67108864 bytes"),
                  std::string::npos)
            << e.what();
    }
    // A FIFO: read through the bound as well.
    const fs::path fifo = dir / "fifo.json";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    r = test::run_command("{ '" + std::string(KEITHRAY_EXE) + "' render '" + fifo.string() + "' -q & head -c 70000000 /dev/zero > '" +
                              fifo.string() + "'; wait $!; }",
                          dir);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("scene file longer than 67108864 bytes"), std::string::npos) << r.err;
    // A directory.
    r = cli("render '" + dir.string() + "' -q");
    EXPECT_NE(r.err.find("cannot read scene file: it is a directory"), std::string::npos) << r.err;
}

TEST(RenderMemory, EstimateCoversTheRenderState) {
    RenderState state(64, 32);
    const uint64_t held = state.radiance_sum().capacity() * sizeof(Color) +
                          state.radiance_compensation().capacity() * sizeof(Color) + state.depth_sum().capacity() * 8 +
                          state.luminance_sq_sum().capacity() * 8 + state.radiance_sq_sum().capacity() * sizeof(Color) +
                          state.sample_count().capacity() * 4 + state.sample_index().capacity() * 4;
    EXPECT_EQ(held, 64u * 32u * 96u);
    EXPECT_GE(kRenderStateBytesPerPixel, 96u + 1u);
    EXPECT_GT(render_memory_bytes(64, 32, false), 64u * 32u * kRenderStateBytesPerPixel);
    EXPECT_GT(render_memory_bytes(64, 32, true), render_memory_bytes(64, 32, false));
    // The loader's largest image needs more than 100 GiB: refused on most machines.
    EXPECT_GT(render_memory_bytes(kMaxDimension, kMaxDimension, false), uint64_t(100) << 30);
    const MemoryLimit limit = memory_limit();
    EXPECT_GT(limit.bytes, 0u);
    EXPECT_FALSE(limit.what.empty());
    EXPECT_EQ(format_bytes(512), "512 B");
    EXPECT_EQ(format_bytes(uint64_t(3) << 29), "1.5 GiB");
}

#ifndef KR_TEST_SANITIZED
// Under an address-space limit the render is refused before any allocation, naming the need
// and the limit.
TEST_F(Hostile, RenderTooLargeForTheLimitIsRefusedUpFront) {
    const fs::path scene = write("huge.json", scene_with("32768, 32768"));
    const test::CommandResult r = test::run_command(
        "ulimit -v 4194304; '" + std::string(KEITHRAY_EXE) + "' render '" + scene.string() + "' -q", dir);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("huge.json: not enough memory for the render of a 32768x32768 image: it needs about"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("above the address-space limit (ulimit -v) (4.0 GiB)"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out.ppm"));
}

// A scene whose JSON fits the size limit but not memory: "not enough memory for the scene".
TEST_F(Hostile, SceneTooLargeForMemorySaysSo) {
    std::string json = "{\"cameras\": [";
    json.reserve(61 << 20);
    while (json.size() < (60u << 20)) json += "[],";
    json += "[]]}";
    const fs::path scene = write("wide.json", json);
    json.clear();
    json.shrink_to_fit();
    const test::CommandResult r = test::run_command(
        "ulimit -v 1048576; '" + std::string(KEITHRAY_EXE) + "' render '" + scene.string() + "' -q", dir);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("error: " + scene.string() + ": not enough memory for the scene (60.0 MiB of JSON)"),
              std::string::npos)
        << r.err;
}
#endif
