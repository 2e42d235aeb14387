// Parameter table of the ray-traced view (MeshLab dialog and CLI flags). The
// filter adds the scene, material, glossy and display tables in front and
// after it (lightingSceneSpecs, materialSpecs, glossySpecs, displaySpecs).
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "gi/color.h"
#include "gi/pathtrace.h"
#include "gi/render.h"
#include "gi/scene_setup.h"
#include "gi/sky.h"

namespace gi {

namespace {
// The "camera" parameter: where the view comes from (RenderOptions holds the camera itself).
enum class CameraChoice { Frame, LookAt, LayerCamera };
constexpr auto kCameraChoices = makeEnumTable<CameraChoice>({
    {CameraChoice::Frame, "Frame the scene", "framing the scene"},
    {CameraChoice::LookAt, "Look at", "look at"},
    {CameraChoice::LayerCamera, "The layer's camera", "the layer's camera"},
});
}  // namespace

std::vector<ParamSpec> RenderOptions::specs() {
  std::vector<ParamSpec> s;
  s.push_back({.name = "mode", .label = "Rendering method",
               .help = "How each pixel's radiance is computed. 'Whitted' (1980): mirror and glass rays, sharp "
                       "shadows of the lights, no noise, no diffuse interreflection. 'Distributed' (Cook et al. "
                       "1984): sampled soft shadows, glossy reflection, antialiasing and depth of field; still no "
                       "diffuse interreflection. 'Two-pass': eye rays as in 'Distributed', the diffuse light from a "
                       "first pass already on the mesh (run radiosity or photon mapping first). 'Path traced': every "
                       "light path (Kajiya 1986) up to 'Maximum bounces', unbiased within that, with an error bar per "
                       "pixel: the yardstick for the others (in a bright closed room raise the bounces: the log "
                       "says when the light they cut off may exceed the error bars).",
               .type = ParamType::Enum, .def = kRenderModes.index(RenderMode::Distributed),
               .choices = kRenderModes.choices()});
  s.push_back({.name = "width", .label = "Image width (pixels)",
               .help = "Width of the rendered image. An image takes about 24 bytes a pixel while it is computed "
                       "(16384 x 16384: 6.4 GB); one that would not fit in the memory available is refused "
                       "before anything is traced.",
               .type = ParamType::Int, .def = 512, .min = 1, .max = 16384});
  s.push_back({.name = "height", .label = "Image height (pixels)",
               .help = "Height of the rendered image.",
               .type = ParamType::Int, .def = 512, .min = 1, .max = 16384});
  s.push_back({.name = "samples_per_pixel", .label = "Samples per pixel",
               .help = "Eye rays per pixel, spread over the pixel (antialiasing) and the lens. Cost grows linearly; "
                       "the noise of the sampled modes falls as 1/sqrt(N) (path traced) or faster (the others' "
                       "scrambled Sobol points). Whitted needs only a few (edges); path tracing hundreds.",
               .type = ParamType::Int, .def = 16, .min = 1, .max = 1 << 20});
  s.push_back({.name = "camera", .label = "Camera",
               .help = "'Frame the scene': look along the view direction at the centre of the bounding box, from "
                       "just far enough to see all of it. 'Look at': from the eye position towards the target. 'The "
                       "layer's camera': the camera stored with the current layer; in MeshLab set it from the "
                       "current view with Filters > Camera > Set Mesh Camera (its shot widget takes the trackball's "
                       "view). MeshLab 2020.09 cannot keep a camera in a script parameter, so scripts use 'Look at'.",
               .type = ParamType::Enum, .def = kCameraChoices.index(CameraChoice::Frame),
               .choices = kCameraChoices.choices()});
  s.push_back({.name = "view_direction", .label = "View direction (framing)",
               .help = "Direction the camera looks in when framing the scene (the Cornell box is seen along +z).",
               .type = ParamType::Direction, .defVec = glm::vec3(0.f, 0.f, 1.f)});
  s.push_back({.name = "eye", .label = "Eye position (look at)",
               .help = "Camera position for 'Look at' (absolute coordinates).",
               .type = ParamType::Point, .defVec = glm::vec3(0.f)});
  s.push_back({.name = "target", .label = "Target (look at)",
               .help = "The point the camera looks at for 'Look at' (absolute coordinates).",
               .type = ParamType::Point, .defVec = glm::vec3(0.f, 0.f, 1.f)});
  s.push_back({.name = "up", .label = "Up direction",
               .help = "The direction that appears upwards in the image.",
               .type = ParamType::Direction, .defVec = glm::vec3(0.f, 1.f, 0.f)});
  s.push_back({.name = "fov", .label = "Vertical field of view (deg)",
               .help = "Angle between the top and bottom edges of the image (39.3: the Cornell box's published "
                       "camera; small: telephoto, large: wide angle).",
               .type = ParamType::Float, .def = 39.3, .min = 0.1, .max = 179.0});
  s.push_back({.name = "aperture_radius", .label = "Lens aperture radius",
               .help = "Radius of the thin lens (0 = a pinhole: everything sharp). A point at depth z blurs into a "
                       "disk of radius A |1/F - 1/z| (in units of the image plane at distance 1) around its sharp "
                       "image: depth of field. Absolute or % of the bbox diagonal.",
               .type = ParamType::Distance, .def = 0.0, .min = 0.0, .max = 1.0});
  s.push_back({.name = "focus_distance", .label = "Focus distance",
               .help = "Distance F from the lens of the plane that stays sharp; 0 = the distance to the target (look "
                       "at) or to the scene's centre (framing), or 1 scene unit with the layer's camera.",
               .type = ParamType::Distance, .def = 0.0, .min = 0.0, .max = 1000.0});
  s.push_back({.name = "max_depth", .label = "Maximum bounces",
               .help = "Rays a path may spawn by reflection or refraction (mirror, glass, glossy, diffuse); 0 = the "
                       "first hit's direct light only. Paths cut here lose their remaining light (logged). Whitted: "
                       "the depth of the ray tree.",
               .type = ParamType::Int, .def = 32, .min = 0, .max = 100000});
  s.push_back({.name = "max_diffuse_bounces", .label = "Maximum diffuse bounces (path traced)",
               .help = "Diffuse surfaces a path may bounce from; -1 = no limit (the full solution). 0 gives direct "
                       "light plus mirrors, glass and glossy only: the distributed image, with error bars. 1, 2, ... "
                       "add the bounces one by one, like radiosity's bounce count.",
               .type = ParamType::Int, .def = -1, .min = -1, .max = 100000,
               .usedWhen = {{"mode", {kRenderModes.index(RenderMode::PathTraced)}}}});
  s.push_back({.name = "light_samples", .label = "Shadow rays per light",
               .help = "Samples of each area light (and of the sun disk) at the first diffuse surface an eye ray "
                       "meets, per eye ray; deeper surfaces take one. More: smoother soft shadows at fewer eye rays. "
                       "They are weighed against the reflection's own sample (multiple importance sampling, Veach "
                       "1997), so where that finds the light better (light all around: a room whose walls glow) more "
                       "light samples give no gain, even a little more noise (an outside audit: 1.5% to 1.9% in such "
                       "a room at 16 eye rays).",
               .type = ParamType::Int, .def = 1, .min = 1, .max = 4096});
  s.push_back({.name = "whitted_min_weight", .label = "Smallest ray weight (Whitted)",
               .help = "Whitted splits every glass hit into a reflected (Fresnel F) and a refracted (1 - F) ray; a "
                       "branch whose weight (product of the factors) falls below this is not traced (Hall and "
                       "Greenberg 1983). 0 traces every branch up to the maximum bounces: up to 2^depth rays.",
               .type = ParamType::Float, .def = 0.001, .min = 0.0, .max = 1.0,
               .usedWhen = {{"mode", {kRenderModes.index(RenderMode::Whitted)}}}});
  s.push_back({.name = "two_pass_diffuse", .label = "Diffuse light (two-pass)",
               .help = "Where the two-pass mode takes the light of a diffuse surface from (B: the first pass's "
                       "per-vertex radiosity, interpolated over each triangle). 'First pass alone': B (shadows as "
                       "coarse as the mesh). 'Ray-traced direct + stored indirect': sharp shadows from shadow rays, "
                       "the rest from B. '+ caustic map': caustics from a photon map read at each hit point (Jensen "
                       "1996). 'Final gather': direct, caustic map, and rays that read B where they land (smoothest).",
               .type = ParamType::Enum, .def = kTwoPassDiffuse.index(TwoPassDiffuse::Caustics),
               .choices = kTwoPassDiffuse.choices(),
               .usedWhen = {{"mode", {kRenderModes.index(RenderMode::TwoPass)}}}});
  s.push_back({.name = "first_pass_caustics", .label = "First pass has caustics",
               .help = "Whether the stored first pass includes caustics (photon mapping and the reference: yes; "
                       "radiosity: no). If so, and the caustic map is used, they are taken out of the stored "
                       "indirect light so as not to count twice. The filters of this suite say it themselves (the "
                       "per-vertex attribute RadiosityCaustics beside Radiosity), and then this is not used: it is "
                       "for a Radiosity attribute left by another tool.",
               .type = ParamType::Bool, .def = true,
               .usedWhen = {{"mode", {kRenderModes.index(RenderMode::TwoPass)}}}});
  s.push_back({.name = "caustic_photons", .label = "Caustic photons",
               .help = "Photons aimed at the mirrors and glass for the caustic map (two-pass). More: sharper and "
                       "less noisy caustics; about 56 bytes each once stored (refused beyond the memory available). With the photon-mapping filter's "
                       "'Photons emitted', 'Photons per caustic estimate', 'Maximum gather radius' and seed, the "
                       "caustics its first pass stored at the vertices are exactly those taken out (same photons, "
                       "same estimate).",
               .type = ParamType::Int, .def = 200000, .min = 1, .max = 100000000,
               .usedWhen = {{"mode", {kRenderModes.index(RenderMode::TwoPass)}}, {"two_pass_diffuse", {kTwoPassDiffuse.index(TwoPassDiffuse::Caustics), kTwoPassDiffuse.index(TwoPassDiffuse::FinalGather)}}}});
  s.push_back({.name = "caustic_k", .label = "Photons per caustic estimate",
               .help = "Nearest caustic photons read at each hit point (cone filter, Jensen 1996): smaller k is "
                       "sharper and noisier (relative noise about 1/sqrt(k)).",
               .type = ParamType::Int, .def = 128, .min = 1, .max = 512,
               .usedWhen = {{"mode", {kRenderModes.index(RenderMode::TwoPass)}}, {"two_pass_diffuse", {kTwoPassDiffuse.index(TwoPassDiffuse::Caustics), kTwoPassDiffuse.index(TwoPassDiffuse::FinalGather)}}}});
  s.push_back({.name = "caustic_max_radius", .label = "Caustic gather radius",
               .help = "Caustic photons farther than this from a hit point are not read (0 = no limit): keeps "
                       "caustics from bleeding into the dark around them, and makes the search cheap far from them. "
                       "Absolute or % of the bbox diagonal.",
               .type = ParamType::Distance, .def = 0.05, .min = 0.0, .max = 1.0,
               .usedWhen = {{"mode", {kRenderModes.index(RenderMode::TwoPass)}}, {"two_pass_diffuse", {kTwoPassDiffuse.index(TwoPassDiffuse::Caustics), kTwoPassDiffuse.index(TwoPassDiffuse::FinalGather)}}}});
  s.push_back({.name = "gather_rays", .label = "Final-gather rays",
               .help = "Rays per diffuse hit (and per eye ray) for the final gather: cosine-distributed, through "
                       "mirrors and glass, reading the first pass's reflected radiosity where they land; a ray that "
                       "lands within two patch edges (the floor beside a block standing on it) relights that point "
                       "from this view's lights and gathers its indirect light again with one more ray, two levels "
                       "deep, as the first pass's values interpolated over a coarse patch are wrong up close.",
               .type = ParamType::Int, .def = 16, .min = 1, .max = 1 << 16,
               .usedWhen = {{"mode", {kRenderModes.index(RenderMode::TwoPass)}}, {"two_pass_diffuse", {kTwoPassDiffuse.index(TwoPassDiffuse::FinalGather)}}}});
  s.push_back({.name = "vertex_radiance", .label = "Also per-vertex radiance towards the camera",
               .help = "Compute for every vertex the radiance it sends towards the camera (what a mirror vertex "
                       "shows from this viewpoint), with the same method and samples, for the vertex colours. Path "
                       "traced with 2 or more samples: also its standard error (the per-vertex attribute StdError).",
               .type = ParamType::Bool, .def = false});
  for (const ParamSpec& p : PathTraceOptions::specs())
    if (p.name.rfind("sky_", 0) == 0 || p.name.rfind("sun_", 0) == 0) s.push_back(p);
  for (const ParamSpec& p : pointLightSpecs()) s.push_back(p);
  s.push_back(seedSpec("pixel samples, lights and photons"));
  s.push_back({.name = "image_path", .label = "Image file",
               .help = "Where to write the image (a name ending in .png): a PNG (sRGB at the exposure below) and, beside it, the linear "
                       "radiance as a PFM (same name, .pfm) for numerical comparison; path traced, also each pixel's "
                       "standard error as NAME_stderr.png and .pfm. Empty: MeshLab shows the images as raster layers "
                       "only, and the command-line tool writes no image.",
               .type = ParamType::String});
  return s;
}

RenderOptions RenderOptions::fromParams(const ParamValues& v, const Scene& scene, const ShotData* layerCamera) {
  RenderOptions o;
  o.mode = kRenderModes.get(v, "mode");
  o.samplesPerPixel = v.getInt("samples_per_pixel");
  o.maxDepth = v.getInt("max_depth");
  o.maxDiffuseBounces = v.getInt("max_diffuse_bounces");
  o.lightSamples = v.getInt("light_samples");
  o.whittedMinWeight = float(v.getFloat("whitted_min_weight"));
  o.twoPass = kTwoPassDiffuse.get(v, "two_pass_diffuse");
  o.firstPassHasCaustics = v.getBool("first_pass_caustics");
  o.causticPhotons = v.getInt("caustic_photons");
  o.causticK = v.getInt("caustic_k");
  o.causticMaxRadius = v.getFloat("caustic_max_radius");
  o.gatherRays = v.getInt("gather_rays");
  o.vertexRadiance = v.getBool("vertex_radiance");
  const SkySun out = SkySun::fromParams(v);
  o.skyRadiance = out.skyRadiance;
  o.sunDirection = out.sunDirection;
  o.sunIrradiance = out.sunIrradiance;
  o.sunAngularRadiusDeg = out.sunAngularRadiusDeg;
  o.point = pointLightFromParams(v, scene.origin);
  o.seed = uint32_t(v.getInt("seed"));
  const int w = v.getInt("width"), h = v.getInt("height");
  const glm::dvec3 up(v.getVec("up"));
  const double fov = v.getFloat("fov");
  const CameraChoice camera = kCameraChoices.get(v, "camera");
  if (camera == CameraChoice::LookAt) {
    // An eye beyond 1e7 scene diagonals sees the scene below a pixel and
    // starts rays the engine cannot offset (1e30 failed as "an internal
    // error ... a numerical failure"; an outside audit): refused by name.
    const double reach = 1e7 * std::max(sceneDiagonal(scene), 1e-30);
    for (const char* name : {"eye", "target"})
      if (!(glm::length(v.getPoint(name) - scene.origin) <= reach))
        throw std::invalid_argument(std::string("parameter '") + name + "' lies more than 1e7 scene diagonals (" +
                                    std::to_string(reach) + ") from the scene");
    o.camera = Camera::lookAt(v.getPoint("eye"), v.getPoint("target"), up, fov, w, h);
  } else if (camera == CameraChoice::LayerCamera) {
    if (!layerCamera)
      throw std::invalid_argument("the current layer has no camera: set one from the view with Filters > Camera > "
                                  "Set Mesh Camera, or choose 'Frame the scene' or 'Look at'");
    o.camera = Camera::fromShot(*layerCamera, w, h);
  } else {
    const SceneScale sc = sceneScale(scene);  // the vertices faces use
    glm::dvec3 lo = scene.origin, hi = scene.origin;
    if (sc.lo.x <= sc.hi.x) {
      lo = scene.toWorld(glm::vec3(sc.lo));
      hi = scene.toWorld(glm::vec3(sc.hi));
    }
    o.camera = Camera::frame(lo, hi, glm::dvec3(v.getVec("view_direction")), up, fov, w, h);
  }
  o.camera.setLens(v.getFloat("aperture_radius"), v.getFloat("focus_distance"));
  return o;
}

}  // namespace gi
