#include "render/integrators/transport_parts.h"

#include <stdexcept>

namespace vrl {

TransportSelection TransportSelection::parse(std::string_view list) {
    TransportSelection selection;
    selection.enabled.fill(false);
    size_t start = 0;
    while (start <= list.size()) {
        const size_t comma = std::min(list.find(',', start), list.size());
        const std::string_view name = list.substr(start, comma - start);
        bool found = false;
        for (size_t i = 0; i < kTransportPartNames.size(); ++i) {
            if (name == kTransportPartNames[i]) selection.enabled[i] = found = true;
        }
        if (!found) {
            throw std::invalid_argument("unknown transport part '" + std::string(name) +
                                        "' (valid: surface, single, medium-surface, multiple)");
        }
        start = comma + 1;
    }
    return selection;
}

std::string TransportSelection::toString() const {
    std::string out;
    for (size_t i = 0; i < enabled.size(); ++i) {
        if (enabled[i]) out += (out.empty() ? "" : ",") + std::string(kTransportPartNames[i]);
    }
    return out;
}

}  // namespace vrl
