// The stiff-case suite (stiff_cases.h) as GoogleTests: one parameterised
// instance per case, asserting that it passes (every value finite and >= 0,
// every agreement within its stated tolerance, every proven bound holding).
// A case marked with a known issue (StiffCase::knownIssue) that still fails is
// skipped with that text; once the issue is fixed it passes like any other.
// The many-VRL light-tree case runs 10^6 VRLs here to keep the suite near a
// minute on two cores; tests/stiff_table_main.cpp runs it at 10^7 for
// docs/stiff-cases.md.
#include "tests/render/stiff/stiff_cases.h"

#include <gtest/gtest.h>

#include <cctype>
#include <cstdio>
#include <string>

namespace vrl::stiff {
namespace {

class StiffCaseTest : public ::testing::TestWithParam<size_t> {};

TEST_P(StiffCaseTest, Passes) {
    const StiffCase& stiffCase = stiffCases()[GetParam()];
    CaseOptions options;
    options.manyVrls = 1'000'000;
    const CaseResult result = runCase(stiffCase, options);
    std::printf("%s\n", summary(result).c_str());
    if (!result.passed && !stiffCase.knownIssue.empty()) GTEST_SKIP() << "known issue: " << stiffCase.knownIssue;
    EXPECT_TRUE(result.finite) << "a value is NaN or infinite";
    EXPECT_TRUE(result.nonNegative) << "a value is negative";
    for (const Comparison& c : result.comparisons) EXPECT_LE(c.value, c.tolerance) << c.label;
    for (const std::string& f : result.failures) ADD_FAILURE() << f;
    if (result.boundAsserted) {
        EXPECT_EQ(result.boundViolations, 0u) << "of " << result.boundChecks << " bound checks";
    }
    EXPECT_TRUE(result.passed);
}

std::string caseName(const ::testing::TestParamInfo<size_t>& info) {
    const StiffCase& c = stiffCases()[info.param];
    std::string name = c.group + "_";
    for (char ch : c.name) name += std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
    std::string compact;
    for (char ch : name)
        if (ch != '_' || compact.empty() || compact.back() != '_') compact += ch;
    while (!compact.empty() && compact.back() == '_') compact.pop_back();
    return compact + "_" + std::to_string(info.param);
}

INSTANTIATE_TEST_SUITE_P(Stiff, StiffCaseTest, ::testing::Range(size_t(0), stiffCases().size()), caseName);

}  // namespace
}  // namespace vrl::stiff
