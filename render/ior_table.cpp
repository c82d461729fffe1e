#include "render/ior_table.h"

#include <algorithm>
#include <cctype>
#include <string>

namespace vrl {
namespace {

// Mitsuba 0.5 src/bsdfs/ior.h, in its order.
constexpr NamedIor kDielectricIors[] = {
    {"vacuum", 1.0f},      {"helium", 1.000036f},        {"hydrogen", 1.000132f},
    {"air", 1.000277f},    {"carbon dioxide", 1.00045f}, {"water", 1.3330f},
    {"acetone", 1.36f},    {"ethanol", 1.361f},          {"carbon tetrachloride", 1.461f},
    {"glycerol", 1.4729f}, {"benzene", 1.501f},          {"silicone oil", 1.52045f},
    {"bromine", 1.661f},   {"water ice", 1.31f},         {"fused quartz", 1.458f},
    {"pyrex", 1.470f},     {"acrylic glass", 1.49f},     {"polypropylene", 1.49f},
    {"bk7", 1.5046f},      {"sodium chloride", 1.544f},  {"amber", 1.55f},
    {"pet", 1.5750f},      {"diamond", 2.419f},
};

// {name, eta (r, g, b), k (r, g, b)}; Mitsuba's data/ior spectra in linear sRGB.
// Some entries are coatings rather than conductors, and a few channels are
// slightly negative after the projection to RGB; all are kept as published.
const ConductorPreset kConductorPresets[] = {
    {"none", {0.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f}},
    {"a-C", {2.9441f, 2.22715f, 1.96817f}, {0.887433f, 0.799322f, 0.815286f}},
    {"Ag", {0.155265f, 0.116723f, 0.138381f}, {4.82834f, 3.12225f, 2.14695f}},
    {"Al", {1.65746f, 0.880369f, 0.521229f}, {9.22387f, 6.26952f, 4.837f}},
    {"AlAs", {3.6051f, 3.23294f, 2.21756f}, {0.000667025f, -0.00049994f, 0.00742612f}},
    {"AlAs_palik", {3.6051f, 3.23294f, 2.21756f}, {0.000667025f, -0.00049994f, 0.00742612f}},
    {"AlSb", {-0.0485226f, 4.14275f, 4.66977f}, {-0.0363742f, 0.0937665f, 1.30074f}},
    {"AlSb_palik", {-0.0485226f, 4.14275f, 4.66977f}, {-0.0363742f, 0.0937665f, 1.30074f}},
    {"Au", {0.143119f, 0.374957f, 1.44248f}, {3.98316f, 2.38572f, 1.60322f}},
    {"Be", {4.18506f, 3.18506f, 2.78409f}, {3.83544f, 3.01013f, 2.86901f}},
    {"Be_palik", {4.18506f, 3.18506f, 2.78409f}, {3.83544f, 3.01013f, 2.86901f}},
    {"Cr", {4.36968f, 2.9167f, 1.6547f}, {5.20643f, 4.23136f, 3.75495f}},
    {"CsI", {2.1449f, 1.70232f, 1.66242f}, {0.0f, 0.0f, 0.0f}},
    {"CsI_palik", {2.1449f, 1.70232f, 1.66242f}, {0.0f, 0.0f, 0.0f}},
    {"Cu", {0.200438f, 0.924033f, 1.10221f}, {3.91295f, 2.45285f, 2.14219f}},
    {"Cu2O", {3.54928f, 2.95206f, 2.73692f}, {0.113218f, 0.194666f, 0.600168f}},
    {"Cu2O_palik", {3.54928f, 2.95206f, 2.73692f}, {0.113218f, 0.194666f, 0.600168f}},
    {"CuO", {3.24538f, 2.44963f, 2.19741f}, {0.520274f, 0.570737f, 0.717225f}},
    {"CuO_palik", {3.24538f, 2.44963f, 2.19741f}, {0.520274f, 0.570737f, 0.717225f}},
    {"Cu_palik", {0.212684f, 0.919988f, 1.10241f}, {3.92156f, 2.45715f, 2.13665f}},
    {"d-C", {2.71125f, 2.31858f, 2.22886f}, {0.0f, 0.0f, 0.0f}},
    {"d-C_palik", {2.71125f, 2.31858f, 2.22886f}, {0.0f, 0.0f, 0.0f}},
    {"Hg", {2.39893f, 1.44003f, 0.909551f}, {6.32763f, 4.37194f, 3.42179f}},
    {"HgTe", {4.77953f, 3.231f, 2.66003f}, {1.63198f, 1.58082f, 1.72958f}},
    {"HgTe_palik", {4.77953f, 3.231f, 2.66003f}, {1.63198f, 1.58082f, 1.72958f}},
    {"Hg_palik", {2.39893f, 1.44003f, 0.909551f}, {6.32763f, 4.37194f, 3.42179f}},
    {"Ir", {3.08641f, 2.08219f, 1.61789f}, {5.59215f, 4.06718f, 3.26726f}},
    {"Ir_palik", {3.08641f, 2.08219f, 1.61789f}, {5.59215f, 4.06718f, 3.26726f}},
    {"K", {0.0640493f, 0.0464101f, 0.0381842f}, {2.10422f, 1.34894f, 0.913211f}},
    {"K_palik", {0.0640493f, 0.0464101f, 0.0381842f}, {2.10422f, 1.34894f, 0.913211f}},
    {"Li", {0.265787f, 0.19561f, 0.22092f}, {3.54017f, 2.31113f, 1.66859f}},
    {"Li_palik", {0.265787f, 0.19561f, 0.22092f}, {3.54017f, 2.31113f, 1.66859f}},
    {"MgO", {2.08959f, 1.65072f, 1.59488f}, {0.0f, 0.0f, 0.0f}},
    {"MgO_palik", {2.08959f, 1.65072f, 1.59488f}, {0.0f, 0.0f, 0.0f}},
    {"Mo", {4.4837f, 3.52546f, 2.77608f}, {4.11113f, 3.42087f, 3.1506f}},
    {"Mo_palik", {4.4837f, 3.52546f, 2.77608f}, {4.11113f, 3.42087f, 3.1506f}},
    {"Na_palik", {0.0602665f, 0.0561412f, 0.0619909f}, {3.17929f, 2.11248f, 1.57909f}},
    {"Nb", {3.42014f, 2.79019f, 2.39559f}, {3.44138f, 2.73764f, 2.57991f}},
    {"Nb_palik", {3.42014f, 2.79019f, 2.39559f}, {3.44138f, 2.73764f, 2.57991f}},
    {"Ni_palik", {2.36728f, 1.66336f, 1.46706f}, {4.49883f, 3.05016f, 2.34543f}},
    {"Rh", {2.5858f, 1.86019f, 1.55443f}, {6.78229f, 4.70295f, 3.97609f}},
    {"Rh_palik", {2.5858f, 1.86019f, 1.55443f}, {6.78229f, 4.70295f, 3.97609f}},
    {"Se-e", {5.72427f, 4.1654f, 4.08161f}, {0.871375f, 1.10528f, 1.56478f}},
    {"Se-e_palik", {5.72427f, 4.1654f, 4.08161f}, {0.871375f, 1.10528f, 1.56478f}},
    {"Se", {4.05926f, 2.84269f, 2.82076f}, {0.754379f, 0.638515f, 0.521587f}},
    {"Se_palik", {4.05926f, 2.84269f, 2.82076f}, {0.754379f, 0.638515f, 0.521587f}},
    {"SiC", {3.17235f, 2.52597f, 2.47936f}, {7.284e-07f, -6.859e-07f, 1.0015e-05f}},
    {"SiC_palik", {3.17235f, 2.52597f, 2.47936f}, {7.284e-07f, -6.859e-07f, 1.0015e-05f}},
    {"SnTe", {4.52519f, 1.98115f, 1.28168f}, {0.0f, 0.0f, 0.0f}},
    {"SnTe_palik", {4.52519f, 1.98115f, 1.28168f}, {0.0f, 0.0f, 0.0f}},
    {"Ta", {2.06258f, 2.39309f, 2.62807f}, {2.40805f, 1.74137f, 1.94704f}},
    {"Ta_palik", {2.06258f, 2.39309f, 2.62807f}, {2.40805f, 1.74137f, 1.94704f}},
    {"Te-e", {7.50904f, 4.29646f, 2.36987f}, {5.58421f, 4.94762f, 3.99751f}},
    {"Te-e_palik", {7.50904f, 4.29646f, 2.36987f}, {5.58421f, 4.94762f, 3.99751f}},
    {"Te", {7.39084f, 4.4821f, 2.63707f}, {3.25614f, 3.52739f, 3.29217f}},
    {"Te_palik", {7.39084f, 4.4821f, 2.63707f}, {3.25614f, 3.52739f, 3.29217f}},
    {"ThF4", {1.83072f, 1.44223f, 1.38765f}, {0.0f, 0.0f, 0.0f}},
    {"ThF4_palik", {1.83072f, 1.44223f, 1.38765f}, {0.0f, 0.0f, 0.0f}},
    {"TiC", {3.70047f, 2.83744f, 2.5823f}, {3.26569f, 2.35156f, 2.17279f}},
    {"TiC_palik", {3.70047f, 2.83744f, 2.5823f}, {3.26569f, 2.35156f, 2.17279f}},
    {"TiN", {1.64847f, 1.15045f, 1.37978f}, {3.36846f, 1.94349f, 1.10201f}},
    {"TiN_palik", {1.64847f, 1.15045f, 1.37978f}, {3.36846f, 1.94349f, 1.10201f}},
    {"TiO2-e", {3.10656f, 2.51316f, 2.58238f}, {2.89537e-05f, -2.51484e-05f, 0.000177556f}},
    {"TiO2-e_palik", {3.10656f, 2.51316f, 2.58238f}, {2.89537e-05f, -2.51484e-05f, 0.000177556f}},
    {"TiO2", {3.45662f, 2.80171f, 2.90515f}, {0.000102666f, -8.97534e-05f, 0.00063569f}},
    {"TiO2_palik", {3.45662f, 2.80171f, 2.90515f}, {0.000102666f, -8.97534e-05f, 0.00063569f}},
    {"VC", {3.65757f, 2.75273f, 2.53268f}, {3.06835f, 2.19867f, 1.96318f}},
    {"VC_palik", {3.65757f, 2.75273f, 2.53268f}, {3.06835f, 2.19867f, 1.96318f}},
    {"VN", {2.8656f, 2.11918f, 1.94008f}, {3.03233f, 2.05611f, 1.61629f}},
    {"VN_palik", {2.8656f, 2.11918f, 1.94008f}, {3.03233f, 2.05611f, 1.61629f}},
    {"V_palik", {4.27751f, 3.51315f, 2.76113f}, {3.49118f, 2.88936f, 3.1117f}},
    {"W", {4.3707f, 3.3003f, 2.99827f}, {3.50068f, 2.60487f, 2.27319f}},
};

}  // namespace

std::span<const NamedIor> dielectricIors() { return kDielectricIors; }

std::optional<float> lookupDielectricIor(std::string_view name) {
    std::string lower(name);
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
    for (const NamedIor& entry : kDielectricIors)
        if (entry.name == lower) return entry.value;
    return std::nullopt;
}

std::span<const ConductorPreset> conductorPresets() { return kConductorPresets; }

std::optional<ConductorPreset> lookupConductorPreset(std::string_view name) {
    std::string lower(name);
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
    if (lower == "none") return kConductorPresets[0];
    for (const ConductorPreset& preset : kConductorPresets)
        if (preset.name == name) return preset;
    return std::nullopt;
}

}  // namespace vrl
