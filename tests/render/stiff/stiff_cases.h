// Stiff-case suite (numerical stability on extreme inputs): a list of cases,
// each rendering or evaluating something in an extreme configuration and
// checking that every value it produces is finite and non-negative, that it
// agrees with a reference (analytic answer, quadrature, the path tracer, or
// plain VRLs against Lightcuts at threshold 0) within a stated tolerance, and
// that the Lightcuts bounds hold where they are proven (VRL cuts; VPL cuts in isotropic media).
//
// Groups:
//   media     sigma_t from 1e-6 to 1e4, albedo 0 .. 0.9999, HG g from -0.99 to
//             0.99, chromatic media whose channels differ by 1e4
//   geometry  camera rays parallel to, crossing, touching and collinear with
//             VRLs; VRLs of length 1e-7 and 1e4; a camera inside a dense
//             medium; zero-length camera segments; a light inside the medium
//             and on its boundary
//   scale     the same scene with distances x k, coefficients / k, point and
//             spot intensities x k^2 (k = 1e-3, 1e3), for every method
//   tree      one VRL, identical VRLs, collinear VRLs, 10^6 / 10^7 VRLs,
//             fluxes from 1e-30 to 1e30
// Bound checks are part of every case that has a light tree.
//
// The cases: one source per group (stiff_media_cases.cpp, stiff_geometry_cases.cpp,
// stiff_scale_cases.cpp, stiff_tree_cases.cpp) over shared helpers
// (stiff_case_support.h); stiff_cases.cpp lists them and runs them.
// Used by tests/stiff_cases_test.cpp (one GoogleTest per case) and
// tests/stiff_table_main.cpp (the Markdown table in docs/stiff-cases.md).
// Every random stream has a fixed seed, so each case is deterministic.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace vrl::stiff {

// One agreement check: `value` must not exceed `tolerance` (NaN fails).
struct Comparison {
    std::string label;  // what is compared, and the measure ("z", "rel. diff", ...)
    double value = 0.0;
    double tolerance = 0.0;
    bool ok() const { return value <= tolerance; }  // false for NaN
};

struct CaseResult {
    std::string group, name;
    std::string description;     // what the case does and its reference, in words
    uint64_t valuesChecked = 0;  // numbers tested for finiteness and sign
    bool finite = true;          // every checked value finite
    bool nonNegative = true;     // every checked value >= 0
    std::vector<Comparison> comparisons;
    // Bound checks: (node, sample) pairs where bound >= estimate was tested, and
    // how many failed. `boundAsserted`: the bound is proven here (VRL cuts, isotropic VPL cuts), so a
    // violation fails the case; otherwise (HG heuristic) violations are reported.
    uint64_t boundChecks = 0, boundViolations = 0;
    bool boundAsserted = true;
    std::vector<std::string> failures;  // anything else that went wrong
    std::string notes;                  // timings, memory, counts
    std::string knownIssue;             // copied from the StiffCase
    double seconds = 0.0;
    bool passed = false;

    // The comparison with the largest value / tolerance (nullptr if none).
    const Comparison* worst() const;
};

struct CaseOptions {
    // VRLs of the "many VRLs" light-tree case (10^6 in the tests, 10^7 in the table).
    uint64_t manyVrls = 1'000'000;
};

struct StiffCase {
    std::string group, name;
    std::function<void(CaseResult&, const CaseOptions&)> run;
    // Non-empty: the case exposes a known, documented problem and is expected to
    // fail until it is fixed (the tests skip it with this text; the table says so).
    std::string knownIssue = {};
};

// Every case, in table order.
const std::vector<StiffCase>& stiffCases();

// Runs one case: fills group and name, times it, catches exceptions (a failure)
// and decides `passed`.
CaseResult runCase(const StiffCase& stiffCase, const CaseOptions& options = {});

// One-line summary of a result (for test output).
std::string summary(const CaseResult& result);

// Markdown document: a title, `preamble`, and the table
// group | case | checks | agreement (value vs tolerance) | result | time,
// followed by per-case notes.
std::string markdownTable(const std::vector<CaseResult>& results, const std::string& preamble);

}  // namespace vrl::stiff
