// A pinhole or thin-lens camera that generates the eye rays of the ray
// tracer. A point p of the image plane (tangent space, unit distance in front
// of the eye) maps to the pinhole ray eye + t (forward + p.x right + p.y up).
// The thin lens (Cook, Porter and Carpenter 1984, "Distributed Ray Tracing";
// Kolb, Mitchell and Hanrahan 1995) replaces the eye by a disk of radius A
// and keeps sharp the plane at focus distance F: the ray from lens point
// o = A (u right + v up) passes through the pinhole ray's point at depth F.
// A point at depth z then spreads over a disk of radius
//   A |1/F - 1/z|   (tangent-space units; times height / (2 tan(fov/2)) in pixels)
// — its circle of confusion.
#pragma once
#include <optional>

#include <glm/glm.hpp>

#include "gi/raycaster.h"

namespace gi {

// What a MeshLab vcg::Shot holds, as plain numbers (vcg/math/shot.h and
// camera.h of vcglib). Extrinsics: the viewpoint (Shot::GetViewPoint(), i.e.
// Extrinsics.Tra() — NOT the negated TranslationVector of MeshLab's XML
// files) and the rotation whose rows are the camera's x (right), y (up) and
// z axes in world coordinates, z pointing backwards (the camera looks along
// -row 2, as in OpenGL; vcg's Shot::GetViewDir() returns row 2 itself). Intrinsics: focal length and pixel size in mm, the
// principal point and the viewport in pixels, viewport y pointing up.
struct ShotData {
  double viewpoint[3] = {0, 0, 0};
  double rotation[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  // rotation[row][column]
  double focalMm = 0;
  double pixelSizeMm[2] = {0, 0};
  double centerPx[2] = {0, 0};
  int viewportPx[2] = {0, 0};
  bool orthographic = false;  // vcg::Camera::ORTHO (MeshLab's view at the smallest field of view)
};

class Camera {
 public:
  // Perspective look-at camera: vertical field of view in degrees (0, 180).
  // Throws std::invalid_argument for a degenerate view (eye == target, up
  // parallel to the view direction, a bad size or angle).
  static Camera lookAt(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& up, double fovYDeg,
                       int width, int height);
  // Looks along viewDir (world) at the centre of the box, from the nearest
  // distance at which all eight corners are inside the field of view.
  static Camera frame(const glm::dvec3& boxMin, const glm::dvec3& boxMax, const glm::dvec3& viewDir,
                      const glm::dvec3& up, double fovYDeg, int width, int height);
  // From a MeshLab shot, rendered at width x height pixels: the shot's
  // vertical extent is kept and pixels are square, so an image of another
  // aspect ratio than the viewport shows more or less to the sides.
  static Camera fromShot(const ShotData& shot, int width, int height);
  // The shot MeshLab stores with a raster layer rendered by this camera
  // (pixel size 0.0369 mm, MeshLab's default): fromShot(toShot(), width(),
  // height()) gives this camera back, lens aside.
  ShotData toShot() const;

  // Thin lens: aperture radius A and focus distance F (scene units; F = 0
  // keeps the camera's own: the target's distance for lookAt and frame, 1
  // for a layer's camera).
  // A = 0 is a pinhole (every depth sharp).
  void setLens(double apertureRadius, double focusDistance);

  // The eye ray through film position (x, y) in pixels (0,0 = top-left corner
  // of the image, x right, y down; pixel (i, j) covers [i, i+1) x [j, j+1))
  // and lens sample u in [0,1)^2, in the local coordinates of a scene whose
  // origin is `sceneOrigin` and whose local unit is `sceneUnit` world lengths
  // (Scene::origin, Scene::unit). The direction is unit length.
  Ray ray(glm::vec2 film, glm::vec2 lens, const glm::dvec3& sceneOrigin, double sceneUnit = 1.0) const;
  // Film position (pixels) where a world point appears through the pinhole
  // (the lens centre); nothing for points behind the camera.
  std::optional<glm::dvec2> project(const glm::dvec3& world) const;
  // Unit direction from a world point towards the camera (the eye; for an
  // orthographic camera, -forward).
  glm::dvec3 towardsCamera(const glm::dvec3& world) const;
  // Pixels per tangent-space unit, vertically (height / (2 tan(fov/2))).
  double pixelsPerTangent() const { return pixelsPerTan_; }

  int width() const { return width_; }
  int height() const { return height_; }
  const glm::dvec3& eye() const { return eye_; }
  const glm::dvec3& forward() const { return fwd_; }
  const glm::dvec3& right() const { return right_; }
  const glm::dvec3& up() const { return up_; }
  bool orthographic() const { return ortho_; }
  double apertureRadius() const { return aperture_; }
  double focusDistance() const { return focus_; }

 private:
  glm::dvec3 eye_{0.0}, fwd_{0, 0, -1}, right_{1, 0, 0}, up_{0, 1, 0};
  // Film pixel (x, y) -> tangent-space point ((x - cx) / k, (cy - y) / k).
  double pixelsPerTan_ = 1, cx_ = 0, cy_ = 0;
  int width_ = 1, height_ = 1;
  bool ortho_ = false;  // then the "tangent space" is in scene units on the film plane
  double aperture_ = 0, focus_ = 1;
};

}  // namespace gi
