// The <bsdf> and <texture> plugins of Mitsuba 0.5/0.6 scenes, read into
// BsdfDescription and TextureValue with Mitsuba's parameter names and
// defaults (the tables at the top of mitsuba_bsdf_parser.cpp list them).
// Internal to render/; part of the parser behind render/mitsuba_parser.h.
//
//   bsdf    diffuse, dielectric, roughdielectric, conductor, roughconductor,
//           plastic, roughplastic, ward, twosided (one nested bsdf, not
//           transmissive), bumpmap (approximated by its nested bsdf; the note
//           goes into BsdfDescription::approximations), null
//   texture bitmap (filename, wrapMode[U|V], gamma, u/v scale and offset),
//           scale (a nested texture times `scale`)
// Reflectance-like colours take a value (<rgb>, <spectrum>, <float>) or a
// texture (nested <texture name="..."> or <ref name="..." id="..."/>); a
// negative value is an error, a value above 1 a warning. IORs take a number
// or one of Mitsuba's names (render/ior_table.h).
#pragma once

#include "render/scene_io/mitsuba/mitsuba_parse_context.h"

namespace vrl::mitsuba {

// Parses a <bsdf> element (registering its id and those of nested objects).
BsdfDescription parseBsdf(ParseContext& context, const xml::Element& element);

// Parses a <texture> element (registering its id). Its bitmap file must exist.
TextureValue parseTexture(ParseContext& context, const xml::Element& element);

}  // namespace vrl::mitsuba
