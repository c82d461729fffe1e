// util/: the leaf helpers against known values (SHA-256 and CRC-32 test
// vectors), their failure modes (an atomic write that fails leaves the old
// file and no temporary behind) and their contracts (random ids' alphabet, the
// command line's WxH and -D name=value with the messages `vrl render` prints).
#include "tests/support/temp_dir.h"
#include "util/atomic_file.h"
#include "util/command_line.h"
#include "util/duration.h"
#include "util/hash.h"
#include "util/random_id.h"
#include "util/termination_signals.h"
#include "util/strings.h"

#include <gtest/gtest.h>

#include <pthread.h>
#include <sys/prctl.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace vrl {
namespace {

namespace fs = std::filesystem;

std::string readAll(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream out;
    out << in.rdbuf();
    return out.str();
}

size_t filesIn(const fs::path& dir) {
    size_t n = 0;
    for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++n;
    return n;
}

TEST(UtilHash, Sha256MatchesTheStandardVectors) {
    EXPECT_EQ(util::sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
    EXPECT_EQ(util::sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    EXPECT_TRUE(util::isSha256Hex(util::sha256Hex("vrl")));
    EXPECT_FALSE(util::isSha256Hex("BA7816BF8F01CFEA414140DE5DAE2223B00361A396177A9CB410FF61F20015AD"));
    EXPECT_FALSE(util::isSha256Hex("ba7816bf"));
    EXPECT_FALSE(util::isSha256Hex(std::string(64, 'g')));
}

TEST(UtilHash, Crc32MatchesTheCheckValue) {
    EXPECT_EQ(util::crc32Of("123456789"), 0xCBF43926u);  // the CRC-32 check value
    EXPECT_EQ(util::crc32Of(""), 0u);
    const uint8_t bytes[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
    EXPECT_EQ(util::crc32Of(bytes, sizeof bytes), 0xCBF43926u);
}

TEST(UtilRandomId, HexDigitsOfTheAskedLengthAndNotRepeated) {
    std::set<std::string> seen;
    for (int i = 0; i < 100; ++i) {
        const std::string id = util::randomHex(16);
        ASSERT_EQ(id.size(), 16u);
        for (char c : id) EXPECT_TRUE((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f')) << id;
        seen.insert(id);
    }
    EXPECT_EQ(seen.size(), 100u);  // 64 random bits each: a repeat would mean a broken source
    EXPECT_EQ(util::randomHex(0), "");
}

TEST(UtilAtomicFile, WritesWholeFilesAndLeavesNoTemporary) {
    const test::TempDir dir("vrl-util-atomic");
    const fs::path file = dir / "out.bin";
    util::writeFileAtomically(file, std::string("first\0version", 13));
    EXPECT_EQ(readAll(file), std::string("first\0version", 13));
    util::writeFileAtomically(file, "second");
    EXPECT_EQ(readAll(file), "second");
    EXPECT_EQ(filesIn(dir.path()), 1u);
    const fs::path sibling = util::temporarySibling(file);
    EXPECT_EQ(sibling.parent_path(), file.parent_path());
    EXPECT_NE(sibling, util::temporarySibling(file));
}

TEST(UtilAtomicFile, AFailedWriteKeepsTheOldFileAndRemovesTheTemporary) {
    const test::TempDir dir("vrl-util-atomic-fail");
    const fs::path file = dir / "keep.txt";
    util::writeFileAtomically(file, "old");
    EXPECT_THROW(util::writeAtomically(file,
                                       [](const fs::path& temporary) {
                                           std::ofstream(temporary) << "half";
                                           throw std::runtime_error("disk full");
                                       }),
                 std::runtime_error);
    EXPECT_EQ(readAll(file), "old");
    EXPECT_EQ(filesIn(dir.path()), 1u);
    // A folder that does not exist: an error naming the file, nothing written.
    try {
        util::writeFileAtomically(dir / "no-such-dir" / "x.txt", "data");
        FAIL() << "writing into a missing folder must throw";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("no-such-dir"), std::string::npos) << e.what();
    }
    EXPECT_EQ(filesIn(dir.path()), 1u);
}

TEST(UtilStrings, LowerCaseIsAsciiOnly) {
    EXPECT_EQ(util::toLower("RoughPlastic-GGX"), "roughplastic-ggx");
    EXPECT_EQ(util::toLower("\xC3\x89t\xC3\xA9"), "\xC3\x89t\xC3\xA9");  // UTF-8 bytes pass through
    EXPECT_EQ(util::toLower(""), "");
}

TEST(UtilStrings, AbbreviateKeepsShortTextAndCutsLongText) {
    EXPECT_EQ(util::abbreviate("job-1"), "job-1");
    EXPECT_EQ(util::abbreviate(std::string(64, 'x')), std::string(64, 'x'));
    EXPECT_EQ(util::abbreviate(std::string(100, 'x'), 4), "xxxx... (100 bytes)");
}

TEST(UtilSignals, TakesTheFirstSignalAndWakesWait) {
    util::TerminationSignals signals(false);
    EXPECT_EQ(signals.received(), 0);
    EXPECT_EQ(signals.wait(std::chrono::milliseconds(1)), 0);  // nothing yet: the timeout
    std::raise(SIGTERM);
    EXPECT_EQ(signals.wait(std::chrono::seconds(5)), SIGTERM);
    std::raise(SIGINT);  // a second signal is ignored when it does not exit
    EXPECT_EQ(signals.received(), SIGTERM);
    EXPECT_EQ(util::TerminationSignals::exitCode(SIGINT), 130);
    EXPECT_EQ(util::TerminationSignals::exitCode(SIGTERM), 143);
}

TEST(UtilSignals, OnlyOneOwnerAndTheHandlersAreRestored) {
    struct sigaction before {};
    sigaction(SIGINT, nullptr, &before);
    {
        util::TerminationSignals signals;
        EXPECT_THROW(util::TerminationSignals second, std::logic_error);
    }
    struct sigaction after {};
    sigaction(SIGINT, nullptr, &after);
    EXPECT_EQ(after.sa_handler, before.sa_handler);
    util::TerminationSignals again;  // the slot is free once the first is gone
}

TEST(UtilSignalsDeathTest, ASecondInterruptQuitsAtOnce) {
    EXPECT_EXIT(
        {
            util::TerminationSignals signals;
            std::raise(SIGINT);
            std::raise(SIGINT);
            std::_Exit(0);  // not reached
        },
        testing::ExitedWithCode(130), "");
}

TEST(UtilSignals, ExitWithParentIsANoOpOutsideLocalClusters) {
    ::unsetenv("VRL_EXIT_WITH_PARENT");
    EXPECT_TRUE(util::exitWithParent());
    ::setenv("VRL_EXIT_WITH_PARENT", "1", 1);  // a parent pid that is not ours: the parent is gone
    EXPECT_FALSE(util::exitWithParent());
    ::unsetenv("VRL_EXIT_WITH_PARENT");
    prctl(PR_SET_PDEATHSIG, 0);
}

}  // namespace
}  // namespace vrl

TEST(UtilDuration, ParsesUnitsAndRefusesTheRest) {
    using namespace std::chrono_literals;
    EXPECT_EQ(vrl::util::parseDuration("7d"), std::chrono::milliseconds(7 * 86400 * 1000LL));
    EXPECT_EQ(vrl::util::parseDuration("12h"), std::chrono::milliseconds(12 * 3600 * 1000LL));
    EXPECT_EQ(vrl::util::parseDuration("30m"), 30min);
    EXPECT_EQ(vrl::util::parseDuration("90s"), 90s);
    EXPECT_EQ(vrl::util::parseDuration("250ms"), 250ms);
    EXPECT_EQ(vrl::util::parseDuration("0"), 0ms);
    for (const char* bad : {"", "7", "d", "-1d", "1.5h", "7 d", "7w", "99999999999999d"})
        EXPECT_THROW(vrl::util::parseDuration(bad), std::invalid_argument) << bad;
    EXPECT_EQ(vrl::util::formatDuration(std::chrono::milliseconds(3 * 86400 * 1000LL + 4 * 3600 * 1000LL)), "3d 4h");
    EXPECT_EQ(vrl::util::formatDuration(725s), "12m 5s");
    EXPECT_EQ(vrl::util::formatDuration(7s), "7s");
}

// The message a refusal carries, or "" if `parse` accepts.
template <class Parse>
std::string refusal(Parse&& parse) {
    try {
        parse();
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "";
}

TEST(UtilCommandLine, ResolutionIsWxHInDecimalDigits) {
    using vrl::util::parseResolution;
    EXPECT_EQ(parseResolution("640x480"), std::make_pair(640, 480));
    EXPECT_EQ(parseResolution("1x1"), std::make_pair(1, 1));
    EXPECT_EQ(parseResolution("007x08"), std::make_pair(7, 8));
    EXPECT_EQ(parseResolution("0x10"), std::make_pair(0, 10));  // the range is the caller's (or the overload's)
    EXPECT_EQ(parseResolution("999999999x999999999"), std::make_pair(999999999, 999999999));
    for (const char* bad : {"", "x", "640", "640x", "x480", "640X480", "640*480", " 640x480", "640x480 ", "640x480\n",
                            "-640x480", "+640x480", "640x-480", "6.4x480", "640x480x2", "1234567890x1", "1x1234567890",
                            "0x10x"})
        EXPECT_EQ(refusal([&] { parseResolution(bad); }),
                  "--resolution expects WxH (e.g. 640x480), got '" + std::string(bad) + "'")
            << bad;
}

TEST(UtilCommandLine, ResolutionInRangeOrTheRangeIsNamed) {
    using vrl::util::parseResolution;
    EXPECT_EQ(parseResolution("16384x4096", 16384, 64 << 20), std::make_pair(16384, 4096));
    for (const char* bad : {"0x10", "10x0", "16385x1", "1x16385", "16384x16384"})
        EXPECT_EQ(refusal([&] { parseResolution(bad, 16384, 64 << 20); }),
                  "resolution " + std::string(bad) + " is outside the supported range (1..16384 per side, at most " +
                      "67108864 pixels)")
            << bad;
    // A malformed size is refused for its form before its range.
    EXPECT_EQ(refusal([] { parseResolution("100000x", 16384, 64 << 20); }),
              "--resolution expects WxH (e.g. 640x480), got '100000x'");
}

TEST(UtilCommandLine, DefinesAreNameEqualsValue) {
    using vrl::util::parseDefines;
    using Defines = std::map<std::string, std::string>;
    EXPECT_EQ(parseDefines({}), Defines{});
    EXPECT_EQ(parseDefines({"g=0.5", "light=1", "empty=", "eq=a=b"}),
              (Defines{{"g", "0.5"}, {"light", "1"}, {"empty", ""}, {"eq", "a=b"}}));
    EXPECT_EQ(parseDefines({"g=0.1", "g=0.9"}), (Defines{{"g", "0.9"}}));  // the last one wins
    for (const char* bad : {"novalue", "=1", "", "="})
        EXPECT_EQ(refusal([&] { parseDefines({"g=1", bad}); }), "-D expects name=value, got '" + std::string(bad) + "'")
            << bad;
}
