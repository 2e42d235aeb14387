// The filter catalogue: each filter's names, plugin, description and what it
// writes. The descriptions are MeshLab's filterInfo (shown in the filter
// dialog and by `meshlabserver -d`) and the CLI's help: what a student reads
// first, so they state the equation, the method and its cost.
#include "gi/filters.h"

#include <stdexcept>

namespace gi {

const std::vector<FilterDesc>& allFilters() {
  static const std::vector<FilterDesc> f = {
      {FilterKind::AmbientOcclusion, "GI: Ambient Occlusion", "ao", "filter_ambient",
       "per-vertex cosine-weighted ambient occlusion",
       "Per-vertex <b>ambient occlusion</b> by ray casting (Embree): the cosine-weighted fraction of the "
       "hemisphere above each vertex from which the sky is visible,<br>"
       "<i>AO(p) = 1/&pi; &int;<sub>H</sub> V(p,&omega;) cos&theta; d&omega;</i>, 1 = fully open, 0 = closed.<br>"
       "Directions are cosine-distributed (so each ray counts 0 or 1) and come from an Owen-scrambled Sobol "
       "sequence per vertex: the error falls faster than plain Monte Carlo's N<sup>-1/2</sup>. "
       "With a target error each vertex stops as soon as its own standard error is small enough. "
       "Two other estimators (parameter Estimator): <i>shared with neighbours</i> pools the rays of nearby "
       "vertices where their values agree (Lepski's rule; fewest rays on dense scans of 100k vertices and more), "
       "and <i>adaptive strata</i> cuts each hemisphere into strata with one jittered ray each and splits those "
       "an occlusion edge crosses (fewest rays on meshes of a few thousand to 30k vertices; with a target error "
       "the grid is refined round by round, every ray kept). "
       "The result goes to vertex <b>quality</b> (the AO value) and vertex <b>colour</b> (grey, AO x 255).<br>"
       "Unlike MeshLab's depth-map 'Ambient Occlusion' it needs no GPU, is seeded and deterministic, and its "
       "values span [0,1] (MeshLab's top out at 0.25). Other visible layers can occlude (Scene extent).",
       WritesVertexQuality | WritesVertexColor | WritesVertexNormal},
      {FilterKind::AmbientObscurance, "GI: Ambient Obscurance", "obscurance", "filter_ambient",
       "per-vertex ambient obscurance",
       "Per-vertex <b>ambient obscurance</b> (Zhukov, Iones and Kronin 1998; Iones et al. 2003): like ambient "
       "occlusion, but a hit at distance d only darkens by <i>1 - &rho;(d)</i> with "
       "<i>&rho;(d) = min(1, d/d<sub>max</sub>)<sup>k</sup></i>, so far geometry matters less and open scenes "
       "and interiors both look natural. Output: quality = obscurance in [0,1], colour = grey.",
       WritesVertexQuality | WritesVertexColor},
      {FilterKind::SkyLighting, "GI: Sky Lighting", "sky", "filter_ambient",
       "per-vertex irradiance from a uniform sky and a sun",
       "Per-vertex <b>irradiance</b> (W/m<sup>2</sup>) from a uniform sky plus a sun: "
       "<i>E = E<sub>sky</sub> AO + E<sub>sun</sub> &lang;V cos&rang;<sub>sun disk</sub></i>. Soft shadows come "
       "from shadow rays spread over the sun's disk (distributed ray tracing). Quality = luminance of E; "
       "colour = sRGB(exposure &times; E), exposure 0 = automatic.",
       WritesVertexQuality | WritesVertexColor},
      {FilterKind::Thickness, "GI: Thickness (Shape Diameter)", "thickness", "filter_ambient",
       "per-vertex thickness: the shape diameter function",
       "Per-vertex <b>thickness</b> by the <b>shape diameter function</b> (Shapira, Shamir and Cohen-Or 2008): "
       "rays from each vertex into the object, cosine-distributed in a cone around the inward normal, each "
       "measuring the distance to where it leaves the object through the opposite side; the value is their "
       "mean, made robust by keeping only the lengths within one standard deviation of their median.<br>"
       "<i>SDF(p) = E[L(&omega;)]</i>, &omega; in the cone of half-angle &alpha; around -n. A cylinder gives "
       "exactly its diameter for any cone; a slab of thickness t gives 2t/(1 + cos&alpha;), a sphere of radius r "
       "(4r/3)(1 + c + c<sup>2</sup>)/(1 + c), c = cos&alpha; (a narrow cone: t and 2r).<br>"
       "Ray casting on the CPU (Embree): no GPU needed (MeshLab's own shape-diameter filter needs one). "
       "Directions come from an Owen-scrambled Sobol sequence per vertex, seeded and deterministic; with a "
       "target error each vertex stops when the standard error of its mean is that fraction of the mean. "
       "Rays that miss or meet the front of a face (open meshes, inward normals) are left out; a vertex with no "
       "valid ray gets 0.<br>"
       "Output: vertex <b>quality</b> = thickness (mesh units), vertex <b>colour</b> = grey (white = the 99th "
       "percentile), per-vertex attribute <i>StdError</i>. Needs a closed mesh with outward normals.",
       WritesVertexQuality | WritesVertexColor},
      {FilterKind::Radiosity, "GI: Radiosity", "radiosity", "filter_radiosity",
       "the radiosity method: form factors and a solver",
       "<b>Radiosity</b> of diffuse (Lambertian) surfaces: the radiosity equation "
       "<i>B<sub>i</sub> = E<sub>i</sub> + &rho;<sub>i</sub> &sum;<sub>j</sub> F<sub>ij</sub> B<sub>j</sub></i> "
       "in RGB, with B the radiosity (W/m<sup>2</sup>), E the emitted radiosity, &rho; the reflectance and "
       "F<sub>ij</sub> the form factor (the fraction of the energy leaving patch i that reaches patch j).<br>"
       "Each triangle is a patch. <b>Form factors</b>, three ways (parameter 'Form factors'): Monte Carlo rays "
       "from stratified points on patch i in cosine-weighted directions, the fraction landing on patch j being "
       "F<sub>ij</sub> (visibility included; cost n &times; rays); the analytic point-to-polygon factor (Wallace et "
       "al. 1989) at points of patch i, times visibility rays (cost n<sup>2</sup>); or a hemicube (Cohen and "
       "Greenberg 1985) rasterising the scene around patch i (cost n<sup>2</sup> &times; resolution). "
       "<b>Direct light</b> is computed apart, with the exact point-to-triangle form factor to each "
       "emitter and shadow rays (small lights would be missed by the F rays), and the solver finds the reflected "
       "radiosity. <b>Solvers</b>: Jacobi (one sweep = one more bounce), Gauss-Seidel (uses new values at once: "
       "fewer sweeps), progressive refinement (Cohen et al. 1988: shoot the patch with the most unshot power). "
       "<b>Bounces</b> 0 shows direct light only, 1, 2, 3... the course's sequence; -1 iterates to the "
       "tolerance. The form factors are kept in a sparse matrix while it fits the memory budget; beyond it, "
       "progressive refinement computes them on the fly.<br>"
       "<b>Emitters</b>: select the light's faces, or give them a face quality above a threshold. "
       "<b>Reflectance</b>: face colour, else vertex colour, else a constant (sRGB converted to linear).<br>"
       "Output: vertex <b>quality</b> = luminance of B (W/m<sup>2</sup>); vertex <b>colour</b> = "
       "sRGB(exposure &times; B). Every layer of the scene receives its result.<br>"
       "<b>Adaptive mesh refinement</b> (optional, 'refine'): solve, split the patches where the reflected "
       "radiosity jumps across an edge or differs from its corners' values, or where a shadow boundary crosses "
       "(the vertices see the lights differently), solve again, up to a depth or a patch budget. Red-green "
       "subdivision keeps the mesh free of T-junctions. The refined mesh replaces the layer's geometry; faces keep "
       "their colour, quality and selection, so the filter can be applied again.<br>"
       "<b>For the course</b>: 'Ambient term' adds progressive refinement's estimate of the light not yet shot "
       "(Cohen et al. 1988) for display; 'Snapshot steps' keeps B after chosen sweeps or shots as attributes "
       "Radiosity_step_N; 'Residual per step' writes a CSV; 'Export the linear system' writes F, E, rho and B as "
       "Matrix Market files.",
       WritesVertexQuality | WritesVertexColor | WritesFaceQuality | WritesFaceColor | WritesGeometry},
      {FilterKind::PhotonMapping, "GI: Photon Mapping", "photonmap", "filter_photonmap",
       "photon-mapped radiosity: caustics through mirrors and glass, indirect light",
       "<b>Photon mapping</b> (Jensen 1996) carries the light radiosity cannot: <b>caustics</b>, light focused "
       "by a mirror or glass onto a diffuse surface (paths L S+ D).<br>"
       "<b>Pass 1</b>: photons leave the lights in proportion to their power (emitter faces, and an optional point "
       "or spot light), bounce on diffuse surfaces with Russian roulette (survival = the largest reflectance "
       "channel, power scaled by &rho;/p: unbiased), reflect on <b>mirrors</b> and reflect or refract through "
       "<b>glass</b> (Fresnel reflectance, Snell's law, total internal reflection), and are stored where they land "
       "on diffuse faces: photons that came through mirrors or glass only in the <b>caustic map</b>, those that "
       "bounced off a diffuse surface before in the <b>global map</b> (kd-trees, nanoflann). The caustic photons "
       "are shot only towards the mirror and glass objects (Jensen's projection maps), so small ones still get "
       "many.<br>"
       "<b>Pass 2</b>: at every vertex, <i>B = E + &rho; H</i> with the irradiance H from the direct light "
       "(explicit light sampling with shadow rays: soft shadows), the caustic map (k nearest caustic photons, cone "
       "filter) and the global map (k nearest, <i>H &asymp; &sum; &Phi;<sub>p</sub> / (&pi; r<sub>k</sub>"
       "<sup>2</sup>)</i>), or a <b>final gather</b> that reads it where cosine rays from the vertex land. "
       "<b>Progressive</b> photon mapping (Hachisuka et al. 2008) shoots passes of photons and shrinks a per-vertex "
       "radius (alpha = 2/3) so the estimate converges.<br>"
       "<b>Light paths</b> (Heckbert 1990 notation): with 'Split by light path' the radiosity is also written "
       "as the attributes <i>Radiosity_emitted</i> (L E), <i>Radiosity_direct</i> (L D E: light sampling, or the "
       "direct photons), <i>Radiosity_caustic</i> (L S+ D E: the caustic photons) and <i>Radiosity_indirect</i> "
       "(diffuse interreflection: the global map or the final gather), which sum to Radiosity; progressive "
       "photon mapping keeps its flux per vertex by the same kinds.<br>"
       "<b>Marking mirrors and glass</b>: load them as their own layers and name them (file name or Layer dialog "
       "rename) to match 'Mirror layers' / 'Glass layers' (default: any name containing 'mirror' / 'glass'); set "
       "'Scene extent' to all visible layers. Glass objects must be closed meshes with outward normals. Vertices "
       "on mirrors and glass get no diffuse radiosity (0).<br>"
       "Emitters, reflectance and output conventions are those of 'GI: Radiosity', so the two compare directly.",
       WritesVertexQuality | WritesVertexColor | WritesLayer},
      {FilterKind::PathTracedReference, "GI: Path Traced Reference", "reference", "filter_reference",
       "per-vertex path-traced reference solution with error bars",
       "A <b>reference solution</b> of the rendering equation (Kajiya 1986) at every vertex, for diffuse "
       "surfaces: the yardstick against which radiosity, photon mapping and sky lighting are measured. From each "
       "vertex, paths are traced: at every bounce the lights are sampled directly (next-event estimation) and "
       "combined with the cosine-sampled direction by <b>multiple importance sampling</b> (Veach 1997); paths end "
       "by <b>Russian roulette</b>, which keeps the estimate unbiased. Lights: the emitter faces, a uniform sky, "
       "a sun disk (soft shadows) and a point or spot light. <b>Mirrors and glass</b> (layers named as in 'GI: "
       "Photon Mapping') are followed specularly (Fresnel, refraction, total internal reflection): caustics "
       "converge, slowly, where photon mapping is fast.<br>"
       "Output: vertex <b>quality</b> = luminance of the radiosity B (W/m<sup>2</sup>), vertex <b>colour</b> = "
       "sRGB(exposure &times; B), and the per-vertex attributes <i>StdError</i> (standard error of the quality, an "
       "honest Monte Carlo error bar) and <i>Paths</i>. With a target relative error, each vertex traces paths "
       "until its error bar is small enough. With 'Split by light path' each path's light is also sorted by the "
       "bounces it took before the vertex (Heckbert 1990 notation): an emitter, the sky or the sun reached from "
       "the vertex itself is <i>Radiosity_direct</i> (L D E), through mirror, glass and glossy bounces only "
       "<i>Radiosity_caustic</i> (L S+ D E), after another diffuse bounce <i>Radiosity_indirect</i>; with "
       "<i>Radiosity_emitted</i> (L E) they sum to Radiosity. The quality and its error bar are also kept as "
       "<i>Reference</i> and <i>ReferenceStdError</i>, which no other filter overwrites: run a method after it "
       "on the same layer and 'GI: Error Map' compares the two.",
       WritesVertexQuality | WritesVertexColor},
      {FilterKind::FormFactorsOfFace, "GI: Form Factors of Selected Face", "formfactors", "filter_radiosity",
       "form factors from one face to every other face (teaching, debugging)",
       "The <b>form factors</b> F<sub>ij</sub> from the selected face i to every other face j: the fraction of "
       "the power leaving i (a Lambertian emitter) that arrives at j, visibility included. Written to face "
       "<b>quality</b> (and grey face colour, the selected face red); vertex quality gets the area-weighted mean "
       "of the incident faces. The log gives the row sum (1 in a closed room, less where light escapes) and the "
       "<b>reciprocity</b> error |A<sub>i</sub> F<sub>ij</sub> - A<sub>j</sub> F<sub>ji</sub>| / A<sub>i</sub> "
       "F<sub>ij</sub> over the strongest receivers. Compare the three methods (Monte Carlo rays, analytic "
       "point-to-polygon, hemicube) on the same face to see their errors and artefacts.",
       WritesVertexQuality | WritesFaceQuality | WritesFaceColor},
      {FilterKind::RayTracedView, "GI: Ray Traced View", "render", "filter_raytrace",
       "an image ray traced from a camera: Whitted, distributed, two-pass or path traced",
       "The <b>eye pass</b>: an image of the scene seen from a camera, each pixel the radiance "
       "<i>L(x, &omega;)</i> arriving along eye rays (the rendering equation, Kajiya 1986). Four methods, as in "
       "the course: <b>Whitted</b> ray tracing (1980: perfect mirror and glass rays, Fresnel and Snell, sharp "
       "shadows, no noise); <b>distributed</b> ray tracing (Cook, Porter and Carpenter 1984: soft shadows, "
       "<b>glossy</b> reflection, antialiasing, depth of field through a thin lens, all sampled); "
       "<b>two-pass</b> (Chen et al. 1991; Jensen 1996): eye rays through mirrors and glass, the diffuse light "
       "from a first pass already on the mesh (run 'GI: Radiosity' or 'GI: Photon Mapping' first: they leave the "
       "per-vertex attribute <i>Radiosity</i>), with ray-traced direct light, a caustic photon map or a final "
       "gather; and unbiased <b>path tracing</b> with a standard error per pixel, the yardstick for the "
       "others.<br>"
       "<b>Camera</b>: framing the scene, 'Look at' (eye, target, up, field of view: for scripts), or the "
       "layer's camera: set it from the current view with <i>Filters &gt; Camera &gt; Set Mesh Camera</i> "
       "(MeshLab 2020.09 cannot store a camera in a script parameter). <b>Materials</b>: layers named like "
       "the mirror, glass and glossy patterns (GGX microfacet lobe, Walter et al. 2007).<br>"
       "Output: the image as a new <b>raster layer</b> with its camera, and, at the image path, a PNG "
       "(sRGB at the exposure) and the linear radiance as PFM. Optionally each vertex's radiance towards the "
       "camera as vertex colour (what a mirror vertex shows from this viewpoint).",
       WritesVertexQuality | WritesVertexColor | WritesImage},
      {FilterKind::HemicubeOfFace, "GI: Hemicube of Selected Face", "hemicube", "filter_radiosity",
       "the hemicube of one face as pictures: cells by patch, delta form factors, Nusselt's disk",
       "The <b>hemicube</b> (Cohen and Greenberg 1985) of the selected face, made visible: at the face's centre "
       "the scene is rasterised with a depth buffer onto the five faces of a unit hemicube, and each cell adds "
       "its <b>delta form factor</b> to the patch it shows, <i>F<sub>ij</sub> = &sum;<sub>cells showing j</sub> "
       "&Delta;F</i>, with <i>&Delta;F = h<sup>2</sup> / (&pi; (x<sup>2</sup> + y<sup>2</sup> + 1)<sup>2</sup>)"
       "</i> on the top face and <i>y h<sup>2</sup> / (&pi; (x<sup>2</sup> + y<sup>2</sup> + 1)<sup>2</sup>)</i> "
       "on a side (cells of side h at (x, y)). Three pictures, as new <b>raster layers</b> (and PNGs at the image "
       "path): the hemicube unfolded into a cross (the top face in the middle, the sides folded out, the face's "
       "plane at the outer edges) with every cell in the colour of the patch it sees (black: nothing; grey: a "
       "patch's back); the same cells by their delta form factor (a ramp, brightest at the top's centre); and "
       "<b>Nusselt's analogue</b> (Nusselt 1928): each patch projected onto the unit hemisphere around the point "
       "and down onto its base disk, seen from above, where the area it covers divided by &pi; is its form "
       "factor (drawn with one ray per pixel, independently of the hemicube).<br>"
       "The mesh's faces take the colours of the pictures (the selected face white) and the hemicube's "
       "F<sub>ij</sub> as face <b>quality</b> (vertex quality: the mean of the incident faces'), exactly the factors of 'GI: Form Factors of Selected Face' with "
       "the hemicube method and one view. The log compares the two methods patch by patch.",
       WritesVertexQuality | WritesFaceQuality | WritesFaceColor | WritesImage},
      {FilterKind::ErrorMap, "GI: Error Map", "errormap", "filter_reference",
       "per-vertex error of a result against a reference (difference, relative, z-score)",
       "Where is an algorithm wrong? The <b>error map</b> compares a per-vertex value v (the vertex quality a "
       "filter wrote, or a named attribute) with a reference r: an attribute of the same mesh (run 'GI: Path "
       "Traced Reference' first: it leaves <i>Reference</i> and <i>ReferenceStdError</i>; then run the method "
       "under test, e.g. 'GI: Radiosity', on the same layer), or a PLY file of the same mesh. It writes to vertex "
       "<b>quality</b> the difference <i>v - r</i>, the relative difference <i>(v - r) / |r|</i> or the "
       "<b>z-score</b> <i>z = (v - r) / &radic;(s<sub>r</sub><sup>2</sup> + s<sub>v</sub><sup>2</sup>)</i> with "
       "the standard errors s of the reference and, if noisy, of the value. Where v is right, z is about "
       "N(0,1) and only 0.27% of the vertices have |z| &gt; 3 by chance: more show a real error (bias, a leak, a "
       "missing caustic), not noise. Vertex <b>colour</b>: a diverging ramp (Moreland 2009), blue below the "
       "reference, white on it, red above, over a symmetric range [-R, R] stated in the log. The log gives the "
       "RMS error, the relative RMS error, the largest |v - r|, the mean difference (bias) and, for z-scores, "
       "the fraction with |z| &gt; 3.",
       WritesVertexQuality | WritesVertexColor},
  };
  return f;
}

const FilterDesc& filterDesc(FilterKind k) {
  for (const auto& d : allFilters())
    if (d.kind == k) return d;
  throw std::logic_error("unknown filter");
}

const FilterDesc* findFilter(const std::string& name) {
  for (const auto& d : allFilters())
    if (d.cliName == name || d.meshlabName == name) return &d;
  return nullptr;
}

std::string cliFilterNames() {
  std::string names;
  for (const auto& d : allFilters()) names += (names.empty() ? "" : ", ") + d.cliName;
  return names;
}

std::vector<FilterKind> pluginFilters(const std::string& plugin) {
  std::vector<FilterKind> out;
  for (const auto& d : allFilters())
    if (d.plugin == plugin) out.push_back(d.kind);
  return out;
}

}  // namespace gi
