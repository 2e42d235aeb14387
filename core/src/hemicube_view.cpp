// The hemicube of one patch and its Nusselt disk as pictures (gi/hemicube_view.h).
#include "gi/hemicube_view.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "gi/sampling.h"

namespace gi {

Rgb8 patchColor(uint32_t id) {
  // Hue anywhere; saturation and value kept high, so that no patch reads as
  // the black of "nothing" or the grey of "a back".
  const float h = toUnitFloat(hash3(id, 0x9e37u, 0x51edu)) * 6.f;
  const float sat = 0.45f + 0.55f * toUnitFloat(hash3(id, 0x1234u, 0x77u));
  const float val = 0.6f + 0.4f * toUnitFloat(hash3(id, 0x4321u, 0x99u));
  const int k = int(h) % 6;
  const float f = h - std::floor(h), p = val * (1 - sat), q = val * (1 - sat * f), t = val * (1 - sat * (1 - f));
  glm::vec3 c;
  switch (k) {
    case 0: c = {val, t, p}; break;
    case 1: c = {q, val, p}; break;
    case 2: c = {p, val, t}; break;
    case 3: c = {p, q, val}; break;
    case 4: c = {t, p, val}; break;
    default: c = {val, p, q}; break;
  }
  auto b = [](float x) { return uint8_t(std::lround(255.f * std::clamp(x, 0.f, 1.f))); };
  return {b(c.r), b(c.g), b(c.b)};
}

glm::vec3 deltaFRamp(float t) {
  // Dark blue, teal, green, yellow (sRGB), linear in between: dark where a
  // cell counts little (the sides' bottom rows), bright at the top's centre.
  static const glm::vec3 stops[] = {{0.05f, 0.03f, 0.25f}, {0.1f, 0.35f, 0.55f}, {0.2f, 0.65f, 0.45f}, {0.99f, 0.9f, 0.15f}};
  t = std::clamp(std::isfinite(t) ? t : 0.f, 0.f, 1.f) * 3.f;
  const int k = std::min(2, int(t));
  const glm::vec3 s = stops[k] + (stops[k + 1] - stops[k]) * (t - float(k));
  return {srgbToLinear(s.r), srgbToLinear(s.g), srgbToLinear(s.b)};
}

namespace {

glm::vec3 linear(Rgb8 c) { return srgb8ToLinear(c.r, c.g, c.b); }

glm::vec3 cellColor(const HemicubeCells::Face& f, size_t k) {
  if (f.patch[k] == kNoHit) return linear(kSeesNothing);
  if (f.back[k]) return linear(kSeesBack);
  return linear(patchColor(f.patch[k]));
}

// The unfolded cross: plane coordinates (X, Y) in [-2, 2]^2, the top face
// on [-1, 1]^2 and each side folded out beyond its edge, the patch's plane
// at the outer border. Gives the hemicube face and its cell, or false for
// the four corners outside the cross.
bool crossCell(const HemicubeCells& c, double X, double Y, int& face, size_t& k) {
  glm::dvec3 d;  // direction in the local frame (t, b, n)
  if (std::fabs(X) <= 1 && std::fabs(Y) <= 1) { face = 0; d = {X, Y, 1}; }
  else if (X > 1 && std::fabs(Y) <= 1) { face = 1; d = {1, Y, 2 - X}; }
  else if (X < -1 && std::fabs(Y) <= 1) { face = 2; d = {-1, Y, 2 + X}; }
  else if (Y > 1 && std::fabs(X) <= 1) { face = 3; d = {X, 1, 2 - Y}; }
  else if (Y < -1 && std::fabs(X) <= 1) { face = 4; d = {X, -1, 2 + Y}; }
  else return false;
  const glm::dvec3 fwd(kHemicubeViews[face][0]), right(kHemicubeViews[face][1]), up(kHemicubeViews[face][2]);
  const double x = glm::dot(d, right) / glm::dot(d, fwd), y = glm::dot(d, up) / glm::dot(d, fwd);
  const HemicubeCells::Face& f = c.faces[size_t(face)];
  const double h = 2.0 / c.resolution, y0 = face == 0 ? -1.0 : 0.0;
  const int i = std::clamp(int(std::floor((x + 1.0) / h)), 0, f.width - 1);
  const int j = std::clamp(int(std::floor((y - y0) / h)), 0, f.height - 1);
  k = size_t(j) * size_t(f.width) + size_t(i);
  return true;
}

}  // namespace

HemicubeView hemicubeView(const Scene& s, const RayCaster& caster, uint32_t face, int resolution, int nusseltResolution) {
  checkCasterFor(s, caster);
  if (face >= s.faceCount()) throw std::invalid_argument("face " + std::to_string(face) + " does not exist");
  FormFactors::Settings set;
  set.method = FormFactorMethod::Hemicube;
  set.hemicubeResolution = resolution;
  set.hemicubePoints = 1;
  const FormFactors ff(s, caster, set);
  HemicubeView v;
  v.cells = ff.hemicubeCells(face);
  const HemicubeCells& c = v.cells;

  // The cross, one pixel per cell (pixel centres are cell centres).
  const int res = c.resolution, W = 2 * res;
  const double h = 2.0 / res, dFtop = h * h / M_PI;  // the largest dF, at the top's centre (h -> 0)
  v.byPatch = Image(W, W);
  v.deltaF = Image(W, W);
  for (int py = 0; py < W; ++py)
    for (int px = 0; px < W; ++px) {
      const double X = -2.0 + (px + 0.5) * h, Y = 2.0 - (py + 0.5) * h;
      int f = 0;
      size_t k = 0;
      if (!crossCell(c, X, Y, f, k)) {
        v.byPatch.at(px, py) = v.deltaF.at(px, py) = linear(kOutside);
        continue;
      }
      v.byPatch.at(px, py) = cellColor(c.faces[size_t(f)], k);
      v.deltaF.at(px, py) = deltaFRamp(float(c.faces[size_t(f)].dF[k] / dFtop));
    }

  // The Nusselt disk seen from above: pixel (u, v) of the unit disk is the
  // direction (u, v, sqrt(1 - u^2 - v^2)) of the local frame; its area h_d^2
  // stands for a projected solid angle h_d^2, so count x h_d^2 / pi -> F.
  const int R = nusseltResolution;
  const double hd = 2.0 / R;
  v.nusseltResolution = R;
  v.nusselt = Image(R, R);
  v.nusseltPatch.assign(size_t(R) * size_t(R), kNoHit);
  std::vector<uint64_t> count(s.faceCount(), 0);
  uint64_t lost = 0;
  Ray ray;
  ray.o = c.eye;
  for (int py = 0; py < R; ++py)
    for (int px = 0; px < R; ++px) {
      const double u = -1.0 + (px + 0.5) * hd, w = 1.0 - (py + 0.5) * hd, r2 = u * u + w * w;
      if (r2 >= 1.0) { v.nusselt.at(px, py) = linear(kOutside); continue; }
      const double z = std::sqrt(1.0 - r2);
      ray.d = glm::normalize(c.t * float(u) + c.b * float(w) + c.n * float(z));
      ray.tnear = 0.f;
      ray.tfar = std::numeric_limits<float>::infinity();
      const Hit hit = caster.intersect(ray);
      Rgb8 col = kSeesNothing;
      if (hit.valid() && hit.face != face) {
        if (glm::dot(faceNormalUnnormalized(s, hit.face), ray.d) < 0.f) {
          col = patchColor(hit.face);
          v.nusseltPatch[size_t(py) * size_t(R) + size_t(px)] = hit.face;
          ++count[hit.face];
        } else {
          col = kSeesBack;
          ++lost;
        }
      } else {
        ++lost;
      }
      v.nusselt.at(px, py) = linear(col);
    }
  // Shares of the disk's pixels (each pixel an equal share of the disk's
  // area): N hd^2 / pi summed to 1.0034 at some resolutions, so a face that
  // sees nothing reported nusselt_lost 1.0034 (an outside audit).
  size_t inside = lost;
  for (size_t j = 0; j < count.size(); ++j) inside += count[j];
  const double share = inside ? 1.0 / double(inside) : 0.0;
  v.nusseltF.resize(s.faceCount());
  for (size_t j = 0; j < count.size(); ++j) v.nusseltF[j] = double(count[j]) * share;
  v.nusseltLost = double(lost) * share;
  return v;
}

std::vector<ParamSpec> hemicubeViewSpecs() {
  return {
      {.name = "face_index", .label = "Face",
       .help = "The face whose hemicube is shown: -1 = the one selected face (MeshLab; none or several selected is "
               "refused), else its index in the scene, as the form-factor filter counts it (the command-line tool "
               "needs it).",
       .type = ParamType::Int, .def = -1, .min = -1, .max = 2147483647},
      {.name = "hemicube_resolution", .label = "Hemicube resolution",
       .help = "Cells across the hemicube's top face (the sides have half as many rows; rounded down to an even "
               "number). The pictures have one pixel per cell: the unfolded cube is 2 x resolution pixels wide. "
               "32 shows the cells and their aliasing plainly; 128 is the form-factor filter's default. The "
               "per-patch sums are exactly that filter's hemicube factors (one view, hemicube_points = 1).",
       .type = ParamType::Int, .def = 128, .min = 4, .max = 2048},
      {.name = "nusselt_resolution", .label = "Nusselt disk pixels",
       .help = "Pixels across the Nusselt disk picture (one ray each, from the patch's centre through the pixel's "
               "place on the hemisphere). A patch's covered area / pi is its form factor from the centre, within "
               "the pixels its outline crosses: about 2 L h / pi for an outline of length L and pixels of side "
               "h = 2 / this.",
       .type = ParamType::Int, .def = 512, .min = 16, .max = 4096},
      {.name = "image_path", .label = "Image file",
       .help = "Where to write the pictures as PNG (a name ending in .png; and beside each a PFM of its linear colours, not of the delta "
               "form factors: those are the faces' quality): the cells by patch "
               "at this path, the delta form factors at NAME_dff.png and the Nusselt disk at NAME_nusselt.png. "
               "Empty: MeshLab shows them as raster layers only, and the command-line tool writes none.",
       .type = ParamType::String},
  };
}

}  // namespace gi
