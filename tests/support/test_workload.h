// How much work the statistical image tests spend, by build.
//
// Contract: kSanitizedBuild is true when the test is compiled with
// AddressSanitizer (GCC's __SANITIZE_ADDRESS__, clang's
// __has_feature(address_sanitizer)), as in the CI's sanitizer job
// (.ci/sanitizers: ASan + UBSan at -O1, where these tests run 6-8x slower:
// 1,473 s of the job's 3,212 s of test time went to vrl_image_test alone). There the
// image tests run the same code paths and the same assertions (every block
// within 5 combined standard errors, measured from the runs) on
// kSanitizedWorkDivisor times fewer samples and lights, and their power checks
// ("the standard error is at most x% of the mean") allow the sqrt of that factor
// more. The sanitizer job checks memory and undefined behaviour; statistical
// power is the main build's job, where nothing changes (divisor 1).
#pragma once

namespace vrl::test {

#if defined(__SANITIZE_ADDRESS__)
#define VRL_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define VRL_TEST_SANITIZED 1
#endif
#endif
#ifdef VRL_TEST_SANITIZED
inline constexpr bool kSanitizedBuild = true;
#else
inline constexpr bool kSanitizedBuild = false;
#endif
#undef VRL_TEST_SANITIZED

// The factor by which a power check's allowed standard error grows, and the
// work divisor it allows: the standard error grows as sqrt(divisor).
inline constexpr float kSanitizedNoiseFactor = kSanitizedBuild ? 2.0f : 1.0f;
inline constexpr int kSanitizedWorkDivisor = int(kSanitizedNoiseFactor * kSanitizedNoiseFactor);

}  // namespace vrl::test
