#include "render/image/metadata.h"

#include <cstdio>
#include <stdexcept>

namespace vrl {

std::string metadataText(const MetadataValue& value) {
    struct Visitor {
        std::string operator()(const std::string& s) const { return s; }
        std::string operator()(int32_t i) const { return std::to_string(i); }
        std::string operator()(float f) const { return format(double(f), 9); }
        std::string operator()(double d) const { return format(d, 17); }
        std::string operator()(const Imath::M44f& m) const {
            std::string out = "[";
            for (int r = 0; r < 4; ++r) {
                out += r ? " [" : "[";
                for (int c = 0; c < 4; ++c) out += (c ? " " : "") + format(double(m[r][c]), 9);
                out += "]";
            }
            return out + "]";
        }
        static std::string format(double v, int digits) {
            char buffer[64];
            std::snprintf(buffer, sizeof buffer, "%.*g", digits, v);
            return buffer;
        }
    };
    return std::visit(Visitor{}, value);
}

double metadataNumber(const MetadataValue& value) {
    if (const auto* i = std::get_if<int32_t>(&value)) return double(*i);
    if (const auto* f = std::get_if<float>(&value)) return double(*f);
    if (const auto* d = std::get_if<double>(&value)) return *d;
    if (const auto* s = std::get_if<std::string>(&value)) {
        size_t used = 0;
        double v = 0.0;
        try {
            v = std::stod(*s, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || used != s->size()) throw std::invalid_argument("metadata '" + *s + "' is not a number");
        return v;
    }
    throw std::invalid_argument("a matrix is not a number");
}

}  // namespace vrl
