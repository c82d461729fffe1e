#include "render/render_method.h"

namespace vrl {

std::vector<std::string> renderMethodNames() {
    std::vector<std::string> names;
    for (RenderMethod m : kRenderMethods) names.emplace_back(methodName(m));
    return names;
}

RenderMethod parseRenderMethod(std::string_view name) {
    for (RenderMethod m : kRenderMethods)
        if (methodName(m) == name) return m;
    std::string valid;
    for (RenderMethod m : kRenderMethods) valid += (valid.empty() ? "" : ", ") + std::string(methodName(m));
    throw std::invalid_argument("unknown method '" + std::string(name.substr(0, 64)) + "' (valid: " + valid + ")");
}

std::string methodsReading(bool MethodReads::*member) {
    std::vector<std::string_view> names;
    bool everyVirtualLightMethod = true;
    for (const MethodTraits& m : kMethodTraits) {
        if (m.reads.*member) names.push_back(m.name);
        else if (m.lights != VirtualLights::None) everyVirtualLightMethod = false;
    }
    if (names.size() > 1 && everyVirtualLightMethod) return "the virtual-light methods";
    std::string out;
    for (size_t i = 0; i < names.size(); ++i)
        out += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + std::string(names[i]);
    return out;
}

}  // namespace vrl
