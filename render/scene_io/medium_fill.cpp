#include "render/scene_io/medium_fill.h"

#include <spdlog/fmt/fmt.h>

#include <charconv>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace vrl {
namespace {

std::vector<std::string_view> split(std::string_view text, char separator) {
    std::vector<std::string_view> parts;
    size_t start = 0;
    while (true) {
        const size_t end = text.find(separator, start);
        parts.push_back(text.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start));
        if (end == std::string_view::npos) return parts;
        start = end + 1;
    }
}

float number(std::string_view text, std::string_view what) {
    while (!text.empty() && text.front() == ' ') text.remove_prefix(1);
    while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
    float value = 0.0f;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || error != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
        throw std::invalid_argument(fmt::format("--medium: {} '{}' is not a finite number", what, text));
    return value;
}

Rgb coefficient(std::string_view text, std::string_view what) {
    const auto parts = split(text, ':');
    if (parts.size() != 1 && parts.size() != 3)
        throw std::invalid_argument(fmt::format("--medium: {} needs one value or r:g:b, got '{}'", what, text));
    const Rgb value = parts.size() == 1 ? Rgb(number(parts[0], what))
                                        : Rgb(number(parts[0], what), number(parts[1], what), number(parts[2], what));
    if (minComponent(value) < 0.0f)
        throw std::invalid_argument(fmt::format("--medium: {} must be non-negative, got '{}'", what, text));
    return value;
}

}  // namespace

MediumDescription parseFillMedium(std::string_view text) {
    MediumDescription medium;
    medium.id = "fill";
    medium.where = {"--medium", 0, std::string(text)};
    bool hasS = false, hasA = false;
    for (std::string_view entry : split(text, ',')) {
        const size_t equals = entry.find('=');
        if (equals == std::string_view::npos)
            throw std::invalid_argument(fmt::format(
                "--medium: '{}' is not name=value (expected \"sigmaS=...,sigmaA=...[,g=...]\")", entry));
        const std::string_view name = entry.substr(0, equals), value = entry.substr(equals + 1);
        if (name == "sigmaS") {
            medium.sigmaS = coefficient(value, name);
            hasS = true;
        } else if (name == "sigmaA") {
            medium.sigmaA = coefficient(value, name);
            hasA = true;
        } else if (name == "g") {
            const float g = number(value, name);
            if (!(g > -1.0f && g < 1.0f)) throw std::invalid_argument(fmt::format("--medium: g must be in (-1, 1), got {}", g));
            if (g != 0.0f) medium.phase = {PhaseDescription::Kind::HenyeyGreenstein, g};
        } else {
            throw std::invalid_argument(fmt::format("--medium: unknown entry '{}' (valid: sigmaS, sigmaA, g)", name));
        }
    }
    if (!hasS || !hasA) throw std::invalid_argument("--medium needs both sigmaS and sigmaA, e.g. \"sigmaS=0.1,sigmaA=0.02\"");
    return medium;
}

void fillWithMedium(SceneDescription& scene, MediumDescription medium) {
    if (!scene.media.empty())
        throw SceneError(scene.media.front().where,
                         fmt::format("--medium fills scenes without media, but this one declares {} (first here)",
                                     scene.media.size()));
    scene.media.push_back(std::move(medium));
    scene.sensor.medium = 0;
    for (auto& emitter : scene.emitters) emitter.medium = 0;
    bool solidGlass = false;
    for (const auto& shape : scene.shapes) {
        const bool glass = shape.bsdf && (shape.bsdf->kind == BsdfDescription::Kind::Dielectric ||
                                          shape.bsdf->kind == BsdfDescription::Kind::RoughDielectric);
        solidGlass = solidGlass || (glass && shape.interiorMedium < 0 && shape.exteriorMedium < 0);
    }
    if (solidGlass)
        scene.approximations.push_back(
            "--medium: glass shapes declare no media, so the fill medium continues inside them");
}

}  // namespace vrl
