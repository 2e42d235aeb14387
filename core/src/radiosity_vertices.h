// The vertex values of a radiosity solution (RadiosityOptions::vertexOutput):
// the direct light at each vertex and the indirect light gathered from the
// patch solution with rays from the vertex, or interpolated from the
// incident patches. Used by every solver (flat and hierarchical).
#pragma once

#include "gi/radiosity.h"
#include "gi/raycaster.h"
#include "gi/run.h"

namespace gi {

// Fills res.Bvertex from the patch solution in res (Rgather, Hindirect,
// ambient) and the vertices' own direct light (the sky through `openings`'
// portals with it, as for the patches); only opt.vertices' vertices.
void radiosityVertexValues(const Scene& s, const RayCaster& caster, const RadiosityOptions& opt, RadiosityResult& res,
                           const Progress& progress = Progress(nullptr), const SkyOpenings* openings = nullptr);

}  // namespace gi
