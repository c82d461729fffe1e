// The stiff-case suite (stiff_cases.h): the registry of every case in table
// order (the groups' sources, stiff_case_groups.h), running one case, and the
// summary line and Markdown table of the results. The helpers the cases share
// and the suite's statistical conventions: stiff_case_support.h.
#include "tests/render/stiff/stiff_cases.h"

#include "tests/render/stiff/stiff_case_groups.h"
#include "tests/render/stiff/stiff_case_support.h"

#include <chrono>
#include <cmath>
#include <exception>
#include <iterator>
#include <sstream>

namespace vrl::stiff {

const Comparison* CaseResult::worst() const {
    const Comparison* w = nullptr;
    double worstRatio = -1.0;
    for (const Comparison& c : comparisons) {
        const double ratio = c.tolerance > 0.0 ? c.value / c.tolerance : (c.value > 0.0 ? kInfinity : 0.0);
        const double key = std::isnan(ratio) ? kInfinity : ratio;
        if (key > worstRatio) worstRatio = key, w = &c;
    }
    return w;
}

namespace {

std::vector<StiffCase> makeCases() {
    std::vector<StiffCase> cases;
    for (const auto& group : {mediaCases, geometryCases, scaleCases, treeCases}) {
        std::vector<StiffCase> groupCases = group();
        cases.insert(cases.end(), std::make_move_iterator(groupCases.begin()),
                     std::make_move_iterator(groupCases.end()));
    }
    return cases;
}

std::string escapeCell(std::string s) {
    std::string out;
    for (char c : s) {
        if (c == '|') out += "\\|";
        else if (c == '\n') out += ' ';
        else out += c;
    }
    return out;
}

std::string shortNumber(double v) {
    if (v == 0.0) return "0";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    if (std::isnan(v)) return "NaN";
    return format("%.3g", v);
}

}  // namespace

const std::vector<StiffCase>& stiffCases() {
    static const std::vector<StiffCase> cases = makeCases();
    return cases;
}

CaseResult runCase(const StiffCase& stiffCase, const CaseOptions& options) {
    CaseResult r;
    r.group = stiffCase.group;
    r.name = stiffCase.name;
    r.knownIssue = stiffCase.knownIssue;
    const auto start = std::chrono::steady_clock::now();
    try {
        stiffCase.run(r, options);
    } catch (const std::exception& e) {
        fail(r, std::string("exception: ") + e.what());
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    bool ok = r.finite && r.nonNegative && r.failures.empty();
    for (const Comparison& c : r.comparisons) ok = ok && c.ok();
    if (r.boundAsserted && r.boundViolations > 0) ok = false;
    r.passed = ok;
    return r;
}

std::string summary(const CaseResult& r) {
    std::ostringstream s;
    s << "[" << r.group << "] " << r.name << ": " << (r.passed ? "pass" : r.knownIssue.empty() ? "FAIL" : "FAIL (known issue)") << " in " << format("%.2f", r.seconds)
      << " s; " << r.valuesChecked << " values (" << (r.finite ? "finite" : "NON-FINITE") << ", "
      << (r.nonNegative ? ">= 0" : "NEGATIVE") << "); " << r.comparisons.size() << " comparisons";
    if (const Comparison* w = r.worst()) s << ", worst: " << w->label << " = " << shortNumber(w->value) << " vs " << shortNumber(w->tolerance);
    s << "; bound " << r.boundViolations << "/" << r.boundChecks << (r.boundAsserted ? " (asserted)" : " (reported)");
    for (const Comparison& c : r.comparisons)
        if (!c.ok()) s << "\n    failed: " << c.label << " = " << shortNumber(c.value) << " > " << shortNumber(c.tolerance);
    for (const std::string& f : r.failures) s << "\n    failure: " << f;
    if (!r.notes.empty()) s << "\n    notes: " << r.notes;
    return s.str();
}

std::string markdownTable(const std::vector<CaseResult>& results, const std::string& preamble) {
    std::ostringstream md;
    md << "# Stiff cases\n\n" << preamble << "\n\n";
    md << "| group | case | checks | agreement (value vs tolerance) | result | time |\n";
    md << "|---|---|---|---|---|---|\n";
    double total = 0.0;
    int passed = 0;
    for (const CaseResult& r : results) {
        std::ostringstream checks;
        checks << r.valuesChecked << " values " << (r.finite ? "finite" : "**not finite**") << ", "
               << (r.nonNegative ? "none < 0" : "**some < 0**") << "; " << r.comparisons.size() << " comparisons";
        if (r.boundChecks > 0)
            checks << "; bound >= estimate " << (r.boundAsserted ? "" : "(heuristic, reported) ") << "on "
                   << r.boundChecks << " samples, " << r.boundViolations << " exceeded";
        std::string agreement = "-";
        if (const Comparison* w = r.worst())
            agreement = escapeCell(w->label) + ": " + shortNumber(w->value) + " vs " + shortNumber(w->tolerance);
        const std::string result = r.passed ? (r.knownIssue.empty() ? "pass" : "pass (known issue not reproduced)")
                                            : (r.knownIssue.empty() ? "**FAIL**" : "**FAIL** (known issue)");
        md << "| " << r.group << " | " << escapeCell(r.name) << " | " << checks.str() << " | " << agreement << " | "
           << result << " | " << format("%.2f s", r.seconds) << " |\n";
        total += r.seconds;
        passed += r.passed;
    }
    int known = 0;
    for (const CaseResult& r : results) known += !r.passed && !r.knownIssue.empty();
    md << "\n" << passed << " of " << results.size() << " cases pass";
    if (known) md << ", " << known << " fail" << (known > 1 ? "" : "s") << " on a known issue (below)";
    md << "; " << format("%.1f", total) << " s in all.\n\n";
    md << "## Cases\n\n";
    for (const CaseResult& r : results) {
        md << "- **" << r.group << " / " << escapeCell(r.name) << "**: " << escapeCell(r.description) << ".";
        if (!r.knownIssue.empty()) md << " Known issue: " << escapeCell(r.knownIssue) << ".";
        if (!r.notes.empty()) md << " Notes: " << escapeCell(r.notes) << ".";
        for (const Comparison& c : r.comparisons)
            if (!c.ok()) md << " Failed: " << escapeCell(c.label) << " = " << shortNumber(c.value) << " > " << shortNumber(c.tolerance) << ".";
        for (const std::string& f : r.failures) md << " Failure: " << escapeCell(f) << ".";
        md << "\n";
    }
    return md.str();
}

}  // namespace vrl::stiff
