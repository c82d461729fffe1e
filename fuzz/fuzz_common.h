// Shared helpers for the libFuzzer targets in fuzz/: a private temporary
// directory per process, silenced logging, and the policy for exceptions.
//
// Policy: a std::exception thrown for bad input is the documented way to refuse
// it and is not a finding. With VRL_FUZZ_STRICT_EXCEPTIONS=1 in the environment,
// an exception of a type the API does not document (see each target) aborts, so
// that the fuzzer reports it; crashes, sanitizer reports, timeouts and
// out-of-memory are always findings.
#pragma once

#include <spdlog/spdlog.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>
#include <system_error>

namespace vrl_fuzz {

inline void quietLogs() { spdlog::set_level(spdlog::level::off); }

inline bool strictExceptions() {
    static const bool strict = [] {
        const char* value = std::getenv("VRL_FUZZ_STRICT_EXCEPTIONS");
        return value != nullptr && std::string(value) == "1";
    }();
    return strict;
}

// VRL_FUZZ_VERBOSE=1: print why each input was refused (to check that seeds
// get as deep as intended: run the fuzzer on the seed files).
inline bool verbose() {
    static const bool on = [] {
        const char* value = std::getenv("VRL_FUZZ_VERBOSE");
        return value != nullptr && std::string(value) == "1";
    }();
    return on;
}
inline void refused(const char* where, const std::exception& e) {
    if (verbose()) std::fprintf(stderr, "==vrl-fuzz== %s refused the input: %s\n", where, e.what());
}
inline void accepted(const char* what) {
    if (verbose()) std::fprintf(stderr, "==vrl-fuzz== accepted: %s\n", what);
}

// An exception the target's API does not document for bad input.
[[noreturn]] inline void undocumented(const char* where, const std::exception& e) {
    std::fprintf(stderr, "==vrl-fuzz== undocumented exception from %s: %s\n", where, e.what());
    std::abort();
}

// A fresh empty directory under $TMPDIR (or /tmp), removed at exit.
class TempDir {
public:
    explicit TempDir(const char* prefix) {
        const char* base = std::getenv("TMPDIR");
        std::string pattern = std::string(base && *base ? base : "/tmp") + "/" + prefix + "-XXXXXX";
        if (::mkdtemp(pattern.data()) == nullptr) {
            std::perror("mkdtemp");
            std::abort();
        }
        path_ = pattern;
    }
    ~TempDir() {
        std::error_code error;
        std::filesystem::remove_all(path_, error);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const std::filesystem::path& path() const { return path_; }

private:
    std::filesystem::path path_;
};

}  // namespace vrl_fuzz
