// Defects of a scene that the filters' set-up mends or warns of, before
// any algorithm runs: faces listed twice (computed once, their copies given
// their originals' values in the output) and a bounding box stretched by
// stray far vertices (the ray offset scales with it).
#pragma once
#include <optional>
#include <string>

#include "gi/filter_run.h"
#include "gi/raycaster.h"

namespace gi::detail {

// Leaves each duplicated face's copies, res.sameFaces (as analyzeScene
// found them), out of the computation (Scene::leftOut), records their own
// vertices in res.sameVertices;
// res.report is made again, the copies counted as left out.
void leaveOutDuplicates(FilterInput& in, FilterResult& res);
// Gives the output's copies their originals' values (per vertex and per
// face); nothing for a refined mesh.
void copyDuplicates(FilterResult& res);
// The face a chosen face stands for: its original where it is a duplicated
// face's copy (left out of the computation), else itself.
uint32_t originalFace(const FilterResult& res, uint32_t face);
// The warning for a bounding box more than 100 times the extent of the bulk of
// the vertices, or none.
std::optional<std::string> strayExtentWarning(const Scene& s, const SceneReport& rep);
// The warning for vertices facing another surface closer than
// kNearOffsets ray offsets along their normal (one ray each), or none:
// surfaces closer than the offset do not see each other, and values near
// them are biased from about ten offsets down (an outside audit: two
// facing squares 1e-5 of the diagonal apart read AO 1 for 0). A surface at
// the vertex itself (a two-sided face's reversed copy, one touching it)
// is not counted.
inline constexpr float kNearOffsets = 10.f;
std::optional<std::string> nearSurfacesWarning(const Scene& s, const RayCaster& caster);
// The warning for emitting faces that overlap another face in one plane,
// facing the same way (a lamp listed twice, triangulated otherwise; a lamp
// quad lying in the ceiling's plane), or none: copies with the same corners
// are left out (leaveOutDuplicates), but these both emit, or hide each
// other by turns, and an outside audit found a lamp modelled twice doubling
// every value without a word. A face overlaps another where its centroid
// lies inside it, within the ray offset of its plane.
std::optional<std::string> overlappingEmittersWarning(const Scene& s);

}  // namespace gi::detail
