#include "gi/camera.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace gi {

namespace {

// Shirley and Chiu 1997, "A Low Distortion Map Between Disk and Square":
// uniform on the unit disk, strata stay compact (good for lens samples).
glm::dvec2 concentricDisk(glm::vec2 u) {
  const double a = 2.0 * u.x - 1.0, b = 2.0 * u.y - 1.0;
  if (a == 0.0 && b == 0.0) return {0.0, 0.0};
  double r, phi;
  if (std::fabs(a) > std::fabs(b)) { r = a; phi = M_PI / 4 * (b / a); }
  else { r = b; phi = M_PI / 2 - M_PI / 4 * (a / b); }
  return {r * std::cos(phi), r * std::sin(phi)};
}

void checkSize(int width, int height) {
  if (width < 1 || height < 1 || width > 65536 || height > 65536)
    throw std::invalid_argument("the image size must be between 1 and 65536 pixels per side (got " +
                                std::to_string(width) + " x " + std::to_string(height) + ")");
}

}  // namespace

Camera Camera::lookAt(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& up, double fovYDeg,
                      int width, int height) {
  checkSize(width, height);
  if (!(fovYDeg > 0.0 && fovYDeg < 180.0)) throw std::invalid_argument("the field of view must lie in (0, 180) degrees");
  const glm::dvec3 d = target - eye;
  const double len = glm::length(d);
  if (!(len > 0.0) || !std::isfinite(len)) throw std::invalid_argument("the camera's eye and target must differ");
  Camera c;
  c.eye_ = eye;
  c.fwd_ = d / len;
  // Only the up direction counts, not its length: a tiny one is as good
  // (it was called parallel to the view, an outside audit found).
  const double upLen = glm::length(up);
  if (!(upLen > 0.0) || !std::isfinite(upLen))
    throw std::invalid_argument("the camera's up direction must be a finite, non-zero vector");
  const glm::dvec3 r = glm::cross(c.fwd_, up / upLen);
  const double rl = glm::length(r);
  if (!(rl > 1e-9)) throw std::invalid_argument("the camera's up direction must not be parallel to its view direction");
  c.right_ = r / rl;
  c.up_ = glm::cross(c.right_, c.fwd_);
  c.width_ = width;
  c.height_ = height;
  c.pixelsPerTan_ = height / (2.0 * std::tan(glm::radians(fovYDeg) / 2.0));
  c.cx_ = width / 2.0;
  c.cy_ = height / 2.0;
  c.focus_ = len;
  return c;
}

Camera Camera::frame(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& viewDir, const glm::dvec3& up,
                     double fovYDeg, int width, int height) {
  const double vl = glm::length(viewDir);
  if (!(vl > 0.0) || !std::isfinite(vl)) throw std::invalid_argument("the view direction must be a non-zero vector");
  const glm::dvec3 fwd = viewDir / vl, c = (lo + hi) * 0.5;
  // Orientation first (at a distance the box's coordinates can resolve: a
  // unit step vanishes beside coordinates of 1e17), then the distance that
  // fits the box.
  const double reach = std::max({1.0, glm::length(c), glm::length(hi - lo)});
  const Camera probe = lookAt(c - fwd * reach, c, up, fovYDeg, width, height);
  const double tanY = height / (2.0 * probe.pixelsPerTan_), tanX = tanY * width / double(height);
  double dist = 0.0, nearest = 0.0;
  for (int k = 0; k < 8; ++k) {
    const glm::dvec3 q((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
    const glm::dvec3 rel = q - c;
    const double x = std::fabs(glm::dot(rel, probe.right_)), y = std::fabs(glm::dot(rel, probe.up_));
    const double z = glm::dot(rel, fwd);
    dist = std::max({dist, x / tanX - z, y / tanY - z});
    nearest = std::max(nearest, -z);
  }
  // 2% margin; and at least a little beyond the nearest corner.
  dist = std::max(dist * 1.02, nearest * 1.02);
  if (!(dist > 0.0)) dist = 1.0;  // a single point
  return lookAt(c - fwd * dist, c, up, fovYDeg, width, height);
}

Camera Camera::fromShot(const ShotData& s, int width, int height) {
  checkSize(width, height);
  const double f = s.focalMm, sx = s.pixelSizeMm[0], sy = s.pixelSizeMm[1];
  const int wv = s.viewportPx[0], hv = s.viewportPx[1];
  if (!(sx > 0.0 && sy > 0.0) || wv < 1 || hv < 1 || (!s.orthographic && !(f > 0.0)))
    throw std::invalid_argument("the view's camera has no valid intrinsics (focal length, pixel size, viewport)");
  Camera c;
  c.eye_ = {s.viewpoint[0], s.viewpoint[1], s.viewpoint[2]};
  glm::dvec3 row[3];
  for (int i = 0; i < 3; ++i) row[i] = {s.rotation[i][0], s.rotation[i][1], s.rotation[i][2]};
  for (int i = 0; i < 3; ++i) {
    const double l = glm::length(row[i]);
    if (!(l > 0.0) || !std::isfinite(l)) throw std::invalid_argument("the view's rotation matrix is degenerate");
    row[i] /= l;
  }
  c.right_ = row[0];
  c.up_ = row[1];
  c.fwd_ = -row[2];  // vcg: camera space z = -(R (p - viewpoint)).z
  c.ortho_ = s.orthographic;
  c.width_ = width;
  c.height_ = height;
  // Viewport pixel (px, py), y up, lies at local (px - cx) sx, (py - cy) sy mm
  // on the plane at focal distance f: tangent (px - cx) sx / f. Orthographic:
  // scene units on the film plane (vcg's SetOrtho stores them as "mm").
  const double unit = s.orthographic ? 1.0 : f;
  const double tanPerImagePx = (double(hv) / height) * sy / unit;  // square image pixels, vertical extent kept
  c.pixelsPerTan_ = 1.0 / tanPerImagePx;
  const double tanXc = (wv / 2.0 - s.centerPx[0]) * sx / unit, tanYc = (hv / 2.0 - s.centerPx[1]) * sy / unit;
  c.cx_ = width / 2.0 - tanXc * c.pixelsPerTan_;
  c.cy_ = height / 2.0 + tanYc * c.pixelsPerTan_;
  c.focus_ = 1.0;
  return c;
}

ShotData Camera::toShot() const {
  ShotData s;
  for (int k = 0; k < 3; ++k) {
    s.viewpoint[k] = eye_[k];
    s.rotation[0][k] = right_[k];
    s.rotation[1][k] = up_[k];
    s.rotation[2][k] = -fwd_[k];
  }
  s.orthographic = ortho_;
  s.pixelSizeMm[0] = s.pixelSizeMm[1] = 0.0369;
  // A tangent-space unit spans pixelsPerTan_ pixels: f = pixelsPerTan_ x pixel size.
  s.focalMm = ortho_ ? 0.0 : pixelsPerTan_ * 0.0369;
  if (ortho_) s.pixelSizeMm[0] = s.pixelSizeMm[1] = 1.0 / pixelsPerTan_;
  s.viewportPx[0] = width_;
  s.viewportPx[1] = height_;
  s.centerPx[0] = cx_;
  s.centerPx[1] = height_ - cy_;  // viewport y points up
  return s;
}

void Camera::setLens(double apertureRadius, double focusDistance) {
  if (!(apertureRadius >= 0.0) || !std::isfinite(apertureRadius))
    throw std::invalid_argument("the aperture radius must be a finite distance >= 0");
  if (!(focusDistance >= 0.0 && std::isfinite(focusDistance)))
    throw std::invalid_argument("the focus distance must be a finite distance >= 0 (0: the camera's own)");
  aperture_ = apertureRadius;
  if (focusDistance > 0.0) focus_ = focusDistance;
}

Ray Camera::ray(glm::vec2 film, glm::vec2 lens, const glm::dvec3& origin, double unit) const {
  const double px = (film.x - cx_) / pixelsPerTan_, py = (cy_ - film.y) / pixelsPerTan_;
  glm::dvec3 o = eye_, d;
  if (ortho_) {
    o += px * right_ + py * up_;
    d = fwd_;
  } else {
    d = fwd_ + px * right_ + py * up_;  // depth 1 along forward
    if (aperture_ > 0.0) {
      const glm::dvec3 focal = eye_ + d * focus_;  // the point kept sharp
      const glm::dvec2 l = concentricDisk(lens) * aperture_;
      o = eye_ + l.x * right_ + l.y * up_;
      d = focal - o;
    }
  }
  Ray r;
  r.o = glm::vec3((o - origin) / unit);
  r.d = glm::vec3(glm::normalize(d));
  return r;
}

std::optional<glm::dvec2> Camera::project(const glm::dvec3& world) const {
  const glm::dvec3 v = world - eye_;
  double x = glm::dot(v, right_), y = glm::dot(v, up_);
  if (!ortho_) {
    const double z = glm::dot(v, fwd_);
    if (!(z > 0.0)) return std::nullopt;
    x /= z;
    y /= z;
  }
  return glm::dvec2(cx_ + x * pixelsPerTan_, cy_ - y * pixelsPerTan_);
}

glm::dvec3 Camera::towardsCamera(const glm::dvec3& world) const {
  if (ortho_) return -fwd_;
  const glm::dvec3 v = eye_ - world;
  const double l = glm::length(v);
  return l > 0.0 ? v / l : -fwd_;
}

}  // namespace gi
