// The benchmark report's scene list: every render's seed is its own and does not
// depend on where the run stands in the sweep; the cheapest points have several renders.
#include "bench/report/benchmark_scenes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

using namespace vrl;
using namespace vrl::report;

namespace {

// The full list names the shared scenes by path only (nothing is loaded here).
std::vector<BenchmarkScene> scenes(bool quick) { return benchmarkScenes(quick, "/repository", "/shared"); }

}  // namespace

TEST(BenchmarkScenes, EveryRenderOfEveryListHasItsOwnSeed) {
    for (const bool quick : {true, false}) {
        const auto list = scenes(quick);
        ASSERT_GE(list.size(), quick ? 2u : 5u);
        std::set<uint64_t> seeds;
        size_t renders = 0, repeated = 0;
        for (const BenchmarkScene& s : list)
            for (const MethodRun& r : s.runs) {
                for (int repeat = 0; repeat < r.repeats; ++repeat) {
                    seeds.insert(runSettings(s, r, repeat).seed);
                    ++renders;
                }
                repeated += r.repeats > 1;
            }
        EXPECT_EQ(seeds.size(), renders) << (quick ? "--quick" : "full");
        EXPECT_GE(repeated, 1u) << (quick ? "--quick" : "full") << ": no point of several renders";
    }
}

TEST(BenchmarkScenes, TheFullReportRendersItsCheapestPointsThreeTimes) {
    // The cheapest settings (cheapPoint, benchmark_scenes.cpp): 57 points in five
    // scenes, three renders each (the two extra renders of the first 53 cost 4.3 min).
    size_t repeated = 0;
    for (const BenchmarkScene& s : scenes(false))
        for (const MethodRun& r : s.runs) {
            EXPECT_TRUE(r.repeats == 1 || r.repeats == 3) << s.name << " " << r.curve() << " " << r.label();
            if (r.repeats == 1) continue;
            ++repeated;
            // Cheap: never the last (most expensive) point of its curve.
            const auto last = std::find_if(s.runs.rbegin(), s.runs.rend(),
                                           [&](const MethodRun& other) { return other.curve() == r.curve(); });
            EXPECT_FALSE(last->label() == r.label()) << s.name << " " << r.curve() << " " << r.label();
            EXPECT_LE(r.spp, 32) << s.name << " " << r.curve() << " " << r.label();
        }
    EXPECT_EQ(repeated, 57u);
}

TEST(BenchmarkScenes, ARunRendersWithTheSameSettingsWhereverItStandsInTheSweep) {
    const auto list = scenes(false);
    const BenchmarkScene& bathroom = list.front();
    ASSERT_GE(bathroom.runs.size(), 3u);
    const MethodRun last = bathroom.runs.back();
    const RenderSettings inFull = runSettings(bathroom, last);
    EXPECT_EQ(inFull.seed, last.seed(bathroom.name));
    // The same run in a sweep with runs removed before it and in reverse order.
    BenchmarkScene shorter = bathroom;
    shorter.runs.erase(shorter.runs.begin(), shorter.runs.begin() + 2);
    std::reverse(shorter.runs.begin(), shorter.runs.end());
    EXPECT_EQ(runSettings(shorter, shorter.runs.front()).seed, inFull.seed);
    // Every run of every scene: its own seed, from its scene, curve and label.
    std::set<uint64_t> seeds;
    for (const BenchmarkScene& s : list)
        for (const MethodRun& r : s.runs) seeds.insert(runSettings(s, r).seed);
    size_t runs = 0;
    for (const BenchmarkScene& s : list) runs += s.runs.size();
    EXPECT_EQ(seeds.size(), runs);
    // The seed changes with the scene, the curve or the label.
    EXPECT_NE(last.seed("another scene"), last.seed(bathroom.name));
    MethodRun otherCurve = last;
    otherCurve.multipleOnly = !otherCurve.multipleOnly;
    EXPECT_NE(otherCurve.seed(bathroom.name), last.seed(bathroom.name));
    MethodRun otherLabel = last;
    otherLabel.spp += 1;
    EXPECT_NE(otherLabel.seed(bathroom.name), last.seed(bathroom.name));
}

TEST(BenchmarkScenes, AListWithARunTwiceOrAShortFirstStageIsRefused) {
    BenchmarkScene s = scenes(true).front();
    EXPECT_NO_THROW(checkScene(s));
    BenchmarkScene twice = s;
    twice.runs.push_back(twice.runs[1]);
    EXPECT_THROW(checkScene(twice), std::logic_error);
    BenchmarkScene shortReference = s;
    shortReference.partReferenceChunks = 7;
    EXPECT_THROW(checkScene(shortReference), std::logic_error);
    BenchmarkScene noRender = s;
    noRender.runs[0].repeats = 0;
    EXPECT_THROW(checkScene(noRender), std::logic_error);
}

TEST(BenchmarkScenes, ASeedIsTheFirst64BitsOfTheSha256OfSceneCurveAndLabel) {
    // Fixed across compilers and standard libraries (no std::hash): the report's
    // runs are the same renders on any machine. The value is Python's
    // int(hashlib.sha256(b"bathroom\npath\n4 spp").hexdigest()[:16], 16).
    MethodRun run;
    run.method = RenderMethod::Path;
    run.spp = 4;
    ASSERT_EQ(run.curve(), "path");
    ASSERT_EQ(run.label(), "4 spp");
    EXPECT_EQ(run.seed("bathroom"), 16721067455369837397ull);
    // A point's second render: int(hashlib.sha256(b"bathroom\npath\n4 spp\nrepeat 1").hexdigest()[:16], 16).
    EXPECT_EQ(run.seed("bathroom", 1), 1214562105443344340ull);
}

TEST(BenchmarkScenes, AVplRunCanAskForItsDistanceSamples) {
    const BenchmarkScene s = scenes(false).front();
    MethodRun run;
    run.method = RenderMethod::VplLightcuts;
    run.lights = 100;
    run.multipleOnly = true;
    // The default: the label (and so the seed) of the reports before distanceSamples existed.
    ASSERT_EQ(run.label(), "N=100 e=0.02 1 spp");
    EXPECT_EQ(runSettings(s, run).vplDistanceSamples, RenderSettings{}.vplDistanceSamples);
    MethodRun fewer = run;
    fewer.distanceSamples = 4;
    EXPECT_EQ(fewer.label(), "N=100 e=0.02 1 spp D=4");
    EXPECT_EQ(runSettings(s, fewer).vplDistanceSamples, 4);
    // Refused where it means nothing or is out of range.
    BenchmarkScene bad = s;
    bad.runs = {fewer};
    EXPECT_NO_THROW(checkScene(bad));
    for (const int d : {-1, kMaxVplDistanceSamples + 1}) {
        bad.runs[0].distanceSamples = d;
        EXPECT_THROW(checkScene(bad), std::logic_error) << d;
    }
    bad.runs[0] = {RenderMethod::VrlLightcuts, 100, 1, 0.02f};
    bad.runs[0].distanceSamples = 4;
    EXPECT_THROW(checkScene(bad), std::logic_error) << "distance samples on VRL Lightcuts";
}

TEST(BenchmarkScenes, EveryVplCurveReachesItsCheapEnd) {
    // Each scene that runs VPL Lightcuts has its D=4 point on every part it runs
    // it on; the paper's scenes keep the whole image's points up to N = 1k.
    for (const BenchmarkScene& s : scenes(false)) {
        std::map<bool, std::vector<std::string>> labels;  // multipleOnly -> labels
        for (const MethodRun& r : s.runs)
            if (r.method == RenderMethod::VplLightcuts) labels[r.multipleOnly].push_back(r.label());
        if (s.name == "bathroom-hg07") {
            EXPECT_TRUE(labels.empty());
            continue;
        }
        EXPECT_EQ(labels[true], (std::vector<std::string>{"N=100 e=0.02 1 spp D=4", "N=100 e=0.02 1 spp",
                                                          "N=1k e=0.02 1 spp"}))
            << s.name;
        std::vector<std::string> whole = {"N=100 e=0.02 1 spp D=4", "N=1k e=0.02 4 spp"};
        if (s.name == "bathroom") whole.push_back("N=10k e=0.02 16 spp");
        EXPECT_EQ(labels[false], whole) << s.name;
    }
}
