// How much work the statistical image tests spend, by build.
//
// Contract: kSanitizedBuild is true when the test is compiled with
// AddressSanitizer (GCC's __SANITIZE_ADDRESS__, clang's
// __has_feature(address_sanitizer)), as in the CI's sanitizer job
// (.ci/sanitizers: ASan + UBSan at -O1, where these tests run 6-8x slower:
// 1,650 s of the job's test time went to vrl_image_test alone). There the
// image tests run the same code paths and the same assertions (every block
// within 5 combined standard errors, measured from the runs) on
// kSanitizedWorkDivisor times fewer samples and lights, and their power checks
// ("the standard error is at most x% of the mean") allow the sqrt of that factor
// more. The sanitizer job checks memory and undefined behaviour; statistical
// power is the main build's job, where nothing changes (divisor 1).
#pragma once

namespace vrl::test {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitizedBuild = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kSanitizedBuild = true;
#else
inline constexpr bool kSanitizedBuild = false;
#endif
#else
inline constexpr bool kSanitizedBuild = false;
#endif

inline constexpr int kSanitizedWorkDivisor = kSanitizedBuild ? 4 : 1;
// The factor by which a power check's allowed standard error grows: sqrt(divisor).
inline constexpr float kSanitizedNoiseFactor = kSanitizedBuild ? 2.0f : 1.0f;
static_assert(kSanitizedNoiseFactor * kSanitizedNoiseFactor == float(kSanitizedWorkDivisor));

}  // namespace vrl::test
