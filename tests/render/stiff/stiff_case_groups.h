// The stiff cases of each group (stiff_cases.h), one source per group, each in
// table order; stiff_cases.cpp concatenates them as media, geometry, scale, tree.
#pragma once

#include "tests/render/stiff/stiff_cases.h"

#include <vector>

namespace vrl::stiff {

std::vector<StiffCase> mediaCases();     // stiff_media_cases.cpp
std::vector<StiffCase> geometryCases();  // stiff_geometry_cases.cpp
std::vector<StiffCase> scaleCases();     // stiff_scale_cases.cpp
std::vector<StiffCase> treeCases();      // stiff_tree_cases.cpp

}  // namespace vrl::stiff
