// Sampled spectra -> linear sRGB, as Mitsuba 0.5/0.6 converts
// <spectrum value="400:0.343, 404:0.445, ..."/> in its RGB build (SPECTRUM_SAMPLES == 3;
// shandler.cpp + Spectrum::fromContinuousSpectrum in src/libcore/spectrum.cpp):
//   1. Samples are (wavelength in nm, value) pairs, wavelengths strictly increasing, at
//      least two. Mitsuba's InterpolatedSpectrum::zeroExtend() then adds a zero sample one
//      mean sample spacing before the first and after the last sample when their values
//      are non-zero, so the spectrum ramps down to zero instead of stopping abruptly.
//   2. Between samples the spectrum is linearly interpolated; it is zero outside them.
//   3. X = ∫ s(λ) x̄(λ) dλ / ∫ ȳ(λ) dλ over 360–830 nm (likewise Y, Z): the CIE 1931 2°
//      colour matching functions at 1 nm (CVRL ciexyz31_1, Mitsuba's own table), linearly
//      interpolated. A spectrum equal to 1 everywhere therefore has Y = 1 ("normalised by
//      the integral of ȳ"; Mitsuba: ProductSpectrum(s, CIE_X).average(360, 830) /
//      CIE_Y.average(360, 830)). The integral here is exact for the piecewise-linear
//      functions; Mitsuba uses adaptive Gauss-Lobatto quadrature to its Epsilon (1e-4).
//   4. XYZ -> linear sRGB (Rec. 709 primaries, D65 white) with Mitsuba's matrix
//      (3.240479, -1.537150, -0.498535 / ...), negative components clamped to zero
//      (Spectrum::clampNegative).
// A flat spectrum is not neutral in sRGB: its white is CIE E, not D65, so a constant 1
// becomes (1.205, 0.948, 0.909). Mitsuba does the same; <spectrum value="0.5"/> (a single
// number) is a different path and stays grey.
// Deliberate deviation: Mitsuba's InterpolatedSpectrum::eval returns
// math::lerp(t, f_b, f_a), i.e. it interpolates every interval backwards (f_b at its left
// end); its own average() interpolates forwards. We interpolate correctly. For the 4 nm
// lajolla vol_cbox reflectances the two differ by at most 5e-4 absolute (0.5%); for
// spectra sampled every 100 nm the difference is large: the vol_cbox light
// "400:0, 500:80, 600:156, 700:184" is (207.8, 108.5, 27.7) here, (183.9, 109.9, 27.5)
// in Mitsuba (red -11.5%).
#pragma once

#include "render/core/rgb.h"

#include <span>
#include <string_view>
#include <vector>

namespace vrl {

struct SpectralSample {
    float wavelength;  // nm
    float value;       // reflectance, radiance, ... in the parameter's own units
};

// Parses Mitsuba's "λ:v, λ:v, ..." (pairs separated by commas and/or whitespace, no
// spaces around ':'). Throws std::invalid_argument naming the offending pair when a pair
// is malformed or not a number, a wavelength is not positive or not strictly increasing,
// a value is negative or not finite, or there are fewer than two pairs.
std::vector<SpectralSample> parseWavelengthSpectrum(std::string_view text);

// CIE XYZ of the spectrum by steps 1-3 above (Y = 1 for a constant 1). Throws
// std::invalid_argument on samples that parseWavelengthSpectrum would reject.
Imath::V3f spectrumToXyz(std::span<const SpectralSample> samples);

// Mitsuba's XYZ -> linear sRGB matrix, without clamping.
Rgb xyzToLinearSrgb(const Imath::V3f& xyz);

// Steps 1-4: linear sRGB, every component >= 0.
Rgb spectrumToRgb(std::span<const SpectralSample> samples);

}  // namespace vrl
