#include "meshlab_bridge.h"

#include <cmath>
#include <memory>
#include <optional>
#include <utility>
#include <stdexcept>

#include <QCoreApplication>
#include <QImage>

#include <cstring>
#include <type_traits>
#include <typeinfo>

#include <vcg/complex/algorithms/update/bounding.h>
#include <vcg/complex/algorithms/update/color.h>
#include <vcg/complex/algorithms/update/normal.h>

#include "vertex_file.h"

namespace gi::ml {

namespace {

// A layer's transformation matrix (CMeshO::Tr): MeshLab shows the layer
// through it, and tools such as Align, the manipulator and the Matrix
// filters set it without moving the vertices until it is frozen. The
// filters see the layers where MeshLab shows them: a second layer moved
// from z = 1 to z = 5 by an unfrozen matrix was lit as if it had not moved
// (an outside audit). Affine matrices only (MeshLab's tools make no other).
struct LayerMatrix {
  glm::dmat3 linear{1.0};
  glm::dvec3 shift{0.0};
  bool identity = true;
  explicit LayerMatrix(const MeshModel& mm) {
    const Matrix44m& T = mm.cm.Tr;
    bool finite = true;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        const double x = double(T[i][j]);
        finite = finite && std::isfinite(x);
        if (x != (i == j ? 1.0 : 0.0)) identity = false;
      }
    if (identity) return;
    const std::string layer = "layer '" + mm.label().toStdString() + "' ";
    if (!finite) throw std::invalid_argument(layer + "has a transformation matrix with a NaN or infinite entry: reset it "
                                             "(Matrix: Reset to Identity) and run the filter again");
    if (T[3][0] != 0 || T[3][1] != 0 || T[3][2] != 0 || T[3][3] != 1)
      throw std::invalid_argument(layer + "has a projective transformation matrix (its last row is not 0 0 0 1): "
                                  "these filters take rotations, scales, shears and translations only");
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) linear[j][i] = double(T[i][j]);  // glm is column-major
      shift[i] = double(T[i][3]);
    }
    const double det = glm::determinant(linear);
    if (!(std::fabs(det) > 0.0) || !std::isfinite(det))
      throw std::invalid_argument(layer + "has a singular transformation matrix (it flattens the layer): reset it "
                                  "(Matrix: Reset to Identity) and run the filter again");
    // A mirror turns the faces' corner order, the side they face, against
    // the normals MeshLab lights them with: which side emits and reflects
    // would be a guess.
    if (det < 0.0)
      throw std::invalid_argument(layer + "has a mirroring transformation matrix (negative determinant) that is not "
                                  "frozen: freeze it (Matrix: Freeze Current Matrix) and check the faces' "
                                  "orientation, or reset it, and run the filter again");
  }
  glm::dvec3 operator()(const Point3m& p) const {
    const glm::dvec3 x{double(p[0]), double(p[1]), double(p[2])};
    return identity ? x : linear * x + shift;
  }
  // A direction of the scene (a normal) back into the layer's own
  // coordinates: normals go by the inverse transpose, so back by the transpose.
  Point3m normalToLayer(const glm::vec3& n) const {
    if (identity) return Point3m(n.x, n.y, n.z);
    glm::dvec3 x = glm::transpose(linear) * glm::dvec3(n);
    const double l = glm::length(x);
    if (l > 0.0) x /= l;
    return Point3m(Scalarm(x.x), Scalarm(x.y), Scalarm(x.z));
  }
};

}  // namespace

std::vector<MeshModel*> participatingLayers(MeshDocument& md, SceneExtent extent, size_t* faceless) {
  std::vector<MeshModel*> out;
  size_t skipped = 0;
  const bool all = extent == SceneExtent::AllVisibleLayers;
  if (all) {
    for (MeshModel* m : compat::meshes(md)) {
      if (!m || !m->isVisible()) continue;
      if (m->cm.fn > 0) out.push_back(m);
      else ++skipped;
    }
  } else if (md.mm()) {
    out.push_back(md.mm());
  }
  if (faceless) *faceless = skipped;
  if (out.empty())
    throw std::invalid_argument(!all ? "no current layer to work on"
                                : skipped ? "no visible layer with faces to work on (" + std::to_string(skipped) +
                                                " without faces: point clouds are neither lit nor occlude)"
                                          : std::string("no visible layer to work on"));
  return out;
}

BridgeScene toScene(const std::vector<MeshModel*>& layers) {
  BridgeScene b;
  // Absolute double coordinates first, re-centred once (precision far from the origin).
  std::vector<glm::dvec3> pts;
  std::vector<glm::uvec3> tris;
  std::vector<glm::vec3> normals;
  bool anyFaceColor = false, anyVertColor = false, anyFaceQuality = false;
  for (MeshModel* mm : layers) {
    anyFaceColor |= mm->hasDataMask(MeshModel::MM_FACECOLOR);
    anyVertColor |= mm->hasDataMask(MeshModel::MM_VERTCOLOR);
    anyFaceQuality |= mm->hasDataMask(MeshModel::MM_FACEQUALITY);
  }
  for (MeshModel* mm : layers) {
    CMeshO& m = mm->cm;
    LayerPart part;
    part.mm = mm;
    part.vertexOffset = pts.size();
    part.faceOffset = tris.size();
    part.sceneVertex.assign(m.vert.size(), -1);
    const LayerMatrix where(*mm);
    const bool vc = mm->hasDataMask(MeshModel::MM_VERTCOLOR);
    const bool fc = mm->hasDataMask(MeshModel::MM_FACECOLOR);
    const bool fq = mm->hasDataMask(MeshModel::MM_FACEQUALITY);
    // Vertex colours that display an earlier result on this layer (its
    // attribute, which readAttributes drops where not every layer has it).
    std::string shows;
    std::vector<glm::u8vec3> layerColors;
    if (vc)
      for (const CVertexO& v : m.vert)
        if (!v.IsD()) layerColors.emplace_back(v.cC()[0], v.cC()[1], v.cC()[2]);
    for (const char* name : kResultAttributes)
      if (shows.empty() && vcg::tri::HasPerVertexAttribute(m, name) && colorsDisplay(name, layerColors)) shows = name;
    if (layers.size() > 1 && b.attrs.vertexColorShows.empty()) b.attrs.vertexColorShows = shows;
    for (size_t i = 0; i < m.vert.size(); ++i) {
      const CVertexO& v = m.vert[i];
      if (v.IsD()) continue;
      part.sceneVertex[i] = int(pts.size());
      pts.push_back(where(v.cP()));
      if (anyVertColor) {
        // Layers without vertex colours count as white-less grey: 188 = 0.5 linear.
        b.attrs.vertexColor.push_back(vc ? glm::u8vec3(v.cC()[0], v.cC()[1], v.cC()[2]) : glm::u8vec3(188));
        b.attrs.vertexColorGiven.push_back(vc && shows.empty() ? 1 : 0);  // the reflectance rule per layer
      }
      b.attrs.vertexSelected.push_back(v.IsS() ? 1 : 0);
    }
    for (size_t i = 0; i < m.face.size(); ++i) {
      const CFaceO& f = m.face[i];
      if (f.IsD()) continue;
      glm::uvec3 t;
      for (int k = 0; k < 3; ++k) t[k] = uint32_t(part.sceneVertex[vcg::tri::Index(m, f.cV(k))]);
      tris.push_back(t);
      if (anyFaceColor) {
        b.attrs.faceColor.push_back(fc ? glm::u8vec3(f.cC()[0], f.cC()[1], f.cC()[2]) : glm::u8vec3(188));
        b.attrs.faceColorGiven.push_back(fc ? 1 : 0);
      }
      if (anyFaceQuality) b.attrs.faceQuality.push_back(fq ? float(f.cQ()) : 0.f);
      b.attrs.faceSelected.push_back(f.IsS() ? 1 : 0);
    }
    part.vertexCount = pts.size() - part.vertexOffset;
    part.faceCount = tris.size() - part.faceOffset;
    b.parts.push_back(std::move(part));
  }
  if (tris.empty()) {
    throw std::invalid_argument(pts.empty() ? "the mesh is empty" : "the mesh has no faces (a point cloud): these filters need triangles");
  }
  // One layer (or all alike): no masks, the one mesh's rule (a single
  // layer's displayed result is found from its attribute, as the CLI does).
  if (layers.size() == 1) b.attrs.vertexColorGiven.clear(), b.attrs.faceColorGiven.clear();
  dropFullColorMasks(b.attrs);
  // MeshLab's coordinates are floats: far from the origin they have
  // already rounded the geometry (gi/scene.h).
  // (A file's double coordinates are rounded too: the gi tool reads them
  // in double; an outside audit found the light 26% larger at 1e6.)
  if (auto far = coarseFloatsWarning(pts))
    b.warnings.push_back("the mesh: " + *far + "; MeshLab holds coordinates as floats and rounds them on loading, even "
                         "from a file with double coordinates: move the mesh near the origin before loading it, or "
                         "run the gi command-line tool, which reads them in double");
  b.scene = Scene::fromAbsolute(pts, std::move(tris));
  return b;
}

void addParams(RichParameterList& out, const std::vector<ParamSpec>& specs, double diagonal) {
  const double d = diagonal > 0 ? diagonal : 1.0;
  for (const ParamSpec& s : specs) {
    const QString name = QString::fromStdString(s.name), label = QString::fromStdString(s.label);
    // The script name in the help: .mlx writers and `meshlabserver -d` readers need it.
    const std::string range = rangeText(s), used = usedWhenText(specs, s, true);
    const QString help = QString::fromStdString(s.help + " [" + (range.empty() ? "" : "range " + range + "; ") +
                                                (used.empty() ? "" : used + "; ") + ".mlx name: " + s.name + "]");
    auto toColor = [](glm::vec3 c) { return QColor(int(std::lround(c.r * 255)), int(std::lround(c.g * 255)), int(std::lround(c.b * 255))); };
    switch (s.type) {
      case ParamType::Bool: out.addParam(RichBool(name, s.def != 0.0, label, help)); break;
      case ParamType::Int: out.addParam(RichInt(name, int(s.def), label, help)); break;
      case ParamType::Float: out.addParam(RichFloat(name, float(s.def), label, help)); break;
      case ParamType::Distance:
        compat::addDistance(out, name, float(s.def * d), float((s.max > 0 ? s.max : 1.0) * d), label, help);
        break;
      case ParamType::Enum: {
        QStringList l;
        for (const auto& c : s.choices) l << QString::fromStdString(c);
        out.addParam(RichEnum(name, int(s.def), l, label, help));
        break;
      }
      case ParamType::Color: out.addParam(RichColor(name, toColor(s.defVec), label, help)); break;
      case ParamType::Direction:
      case ParamType::Point:
        compat::addPoint(out, name, Point3m(s.defVec.x, s.defVec.y, s.defVec.z), s.type == ParamType::Direction, label, help);
        break;
      case ParamType::String: out.addParam(RichString(name, QString::fromStdString(s.defText), label, help)); break;
    }
  }
}

ParamValues readParams(const RichParameterList& in, const std::vector<ParamSpec>& specs) {
  ParamValues v;
  for (const ParamSpec& s : specs) {
    const QString n = QString::fromStdString(s.name);
    if (!in.hasParameter(n)) throw std::invalid_argument("parameter '" + s.name + "' is missing");
    switch (s.type) {
      case ParamType::Bool: v.set(s.name, in.getBool(n)); break;
      case ParamType::Int: v.set(s.name, in.getInt(n)); break;
      case ParamType::Float: v.set(s.name, double(in.getFloat(n))); break;
      case ParamType::Distance: v.set(s.name, double(in.getAbsPerc(n))); break;
      case ParamType::Enum: v.set(s.name, in.getEnum(n)); break;
      case ParamType::Color: {
        QColor c = in.getColor(n);
        // A channel outside 0..255 in a hand-edited .mlx makes Qt's colour
        // invalid, which reads as black: a reflectance of 0 without a word
        // (an outside audit).
        if (!c.isValid())
          throw std::invalid_argument("parameter '" + s.name + "' is not a colour (each channel, alpha included, "
                                      "must lie in 0..255)");
        v.set(s.name, glm::vec3(c.red() / 255.f, c.green() / 255.f, c.blue() / 255.f));
        break;
      }
      case ParamType::Direction: {
        const Point3m p = in.getPoint3m(n);
        v.set(s.name, glm::vec3(float(p[0]), float(p[1]), float(p[2])));
        break;
      }
      case ParamType::Point: {
        const Point3m p = in.getPoint3m(n);
        v.set(s.name, glm::dvec3(double(p[0]), double(p[1]), double(p[2])));
        break;
      }
      case ParamType::String: v.set(s.name, in.getString(n).toStdString()); break;
    }
  }
  return v;
}

double documentDiagonal(MeshDocument& md) {
  // Over the vertices the faces use, as the engine's scale (Scene::fromAbsolute,
  // sceneScale): a vertex no face uses, far away, moves no default. A layer
  // without faces counts by its box only as the current one (the others,
  // point clouds, take no part: participatingLayers).
  vcg::Box3<MESHLAB_SCALAR> box;
  for (MeshModel* m : compat::meshes(md)) {
    if (!(m == md.mm() || m->isVisible())) continue;
    bool faces = false;
    std::optional<LayerMatrix> where;
    try {
      where.emplace(*m);
    } catch (const std::invalid_argument&) {  // the filter refuses it; the dialog's defaults need only a size
    }
    for (const CFaceO& f : m->cm.face) {
      if (f.IsD()) continue;
      for (int k = 0; k < 3; ++k) {
        const glm::dvec3 p = where ? (*where)(f.cP(k)) : glm::dvec3(f.cP(k)[0], f.cP(k)[1], f.cP(k)[2]);
        box.Add(vcg::Point3<MESHLAB_SCALAR>(MESHLAB_SCALAR(p.x), MESHLAB_SCALAR(p.y), MESHLAB_SCALAR(p.z)));
      }
      faces = true;
    }
    if (!faces && m == md.mm()) box.Add(m->cm.Tr, m->cm.bbox);
  }
  const double d = box.IsNull() ? 1.0 : double(box.Diag());
  return d > 0 && std::isfinite(d) ? d : 1.0;
}

namespace {

// Whether the layer holds a per-vertex attribute `name` of another type
// than T (another size, or another type of the same size). vcg's
// GetPerVertexAttribute<T> matches names by size only and, finding none of
// T's size, adds one whose name is taken: that fails (its assert compiled
// out) and hands back the other attribute's storage, which writing T ran
// past: MeshLab crashed (an outside audit: MeshLab's own 'Define New Per
// Vertex Attribute' names its float 'Radiosity' by default, and radiosity
// writes three floats under that name).
template <class T>
bool clashes(const CMeshO& m, const std::string& name) {
  for (const auto& a : m.vert_attr)
    if (a._name == name) return a._sizeof != sizeof(T) || (a._type != typeid(void) && a._type != typeid(T));
  return false;
}

}  // namespace

void checkResultFits(const BridgeScene& b, const FilterResult& r) {
  for (const VertexAttribute& a : r.attributes)
    for (const LayerPart& p : b.parts) {
      const CMeshO& m = p.mm->cm;
      if (a.components == 3 ? clashes<Point3m>(m, a.name) : clashes<Scalarm>(m, a.name))
        throw std::invalid_argument(
            "layer '" + p.mm->label().toStdString() + "' already has a per-vertex attribute '" + a.name +
            "' of another type (this filter writes " + (a.components == 3 ? "three numbers" : "one number") +
            " a vertex under that name): remove or rename that attribute and run the filter again");
    }
}

void writeResult(BridgeScene& b, FilterResult& r) {
  if (r.refined) {
    const RefinedOrder order = replaceWithRefined(b, *r.refined);
    r.reorder(order.vertex, order.face);
  }
  int vmask = 0;
  if (!r.vertexQuality.empty()) vmask |= MeshModel::MM_VERTQUALITY;
  if (!r.vertexColor.empty()) vmask |= MeshModel::MM_VERTCOLOR;
  if (!r.vertexNormal.empty()) vmask |= MeshModel::MM_VERTNORMAL;
  for (LayerPart& p : b.parts) p.mm->updateDataMask(vmask);
  for (LayerPart& p : b.parts) {
    const LayerMatrix where(*p.mm);
    for (size_t i = 0; i < p.mm->cm.vert.size(); ++i) {
      if (p.sceneVertex[i] < 0) continue;
      const size_t s = size_t(p.sceneVertex[i]);
      CVertexO& v = p.mm->cm.vert[i];
      if (!r.vertexQuality.empty()) v.Q() = r.vertexQuality[s];
      if (!r.vertexColor.empty()) v.C() = vcg::Color4b(r.vertexColor[s].r, r.vertexColor[s].g, r.vertexColor[s].b, 255);
      if (!r.vertexNormal.empty()) v.N() = where.normalToLayer(r.vertexNormal[s]);
    }
  }
  if (!r.faceQuality.empty() || !r.faceColor.empty()) {
    for (LayerPart& p : b.parts) {
      p.mm->updateDataMask((r.faceQuality.empty() ? 0 : int(MeshModel::MM_FACEQUALITY)) |
                           (r.faceColor.empty() ? 0 : int(MeshModel::MM_FACECOLOR)));
      CMeshO& m = p.mm->cm;
      size_t k = p.faceOffset;
      for (size_t i = 0; i < m.face.size(); ++i) {
        if (m.face[i].IsD()) continue;
        if (!r.faceQuality.empty()) m.face[i].Q() = r.faceQuality[k];
        if (!r.faceColor.empty()) m.face[i].C() = vcg::Color4b(r.faceColor[k].r, r.faceColor[k].g, r.faceColor[k].b, 255);
        ++k;
      }
    }
  }
  for (const VertexAttribute& a : r.attributes) {
    for (LayerPart& p : b.parts) {
      CMeshO& m = p.mm->cm;
      if (a.components == 3) {
        auto h = vcg::tri::Allocator<CMeshO>::GetPerVertexAttribute<Point3m>(m, a.name);
        for (size_t i = 0; i < m.vert.size(); ++i)
          if (p.sceneVertex[i] >= 0) {
            const float* x = &a.values[size_t(p.sceneVertex[i]) * 3];
            h[m.vert[i]] = Point3m(x[0], x[1], x[2]);
          }
      } else {
        auto h = vcg::tri::Allocator<CMeshO>::GetPerVertexAttribute<Scalarm>(m, a.name);
        for (size_t i = 0; i < m.vert.size(); ++i)
          if (p.sceneVertex[i] >= 0) h[m.vert[i]] = a.values[size_t(p.sceneVertex[i])];
      }
    }
  }
}

ProgressFn progressFrom(vcg::CallBackPos* cb) {
  if (!cb) return nullptr;
  // meshlabserver prints every call's message: pass on only new stages and
  // steps of 5%, which is also all a progress bar needs.
  auto last = std::make_shared<std::pair<int, std::string>>(-100, "");
  auto timeLeft = std::make_shared<TimeLeft>();
  // meshlabserver prints each label as it comes, without a separator.
  const bool server = QCoreApplication::applicationFilePath().endsWith("meshlabserver");
  return [cb, last, server, timeLeft](int pct, const std::string& stage) {
    if (stage == last->second && pct < last->first + 5 && pct < 100) return true;
    *last = {pct, stage};
    const std::string left = timeLeft->text(pct);
    const std::string shown = left.empty() ? stage : stage + ", " + left;
    const std::string label = server ? shown + " " + std::to_string(pct) + "%\n" : shown;
    cb(pct, label.c_str());
    return true;
  };
}

bool guarded(QString& errorMessage, const std::function<void(const std::string&)>& log, const QString& filter,
             const std::function<void()>& body) {
  std::string why;
  try {
    body();
    return true;
  } catch (const std::invalid_argument& e) {
    why = e.what();
  } catch (const Cancelled& e) {
    why = e.what();
  } catch (const std::bad_alloc&) {
    why = "out of memory";
  } catch (const std::exception& e) {
    why = std::string("internal error: ") + e.what();
  }
  errorMessage = filter + ": " + QString::fromStdString(why) + " (the mesh was left unchanged)";
  log(errorMessage.toStdString());
  return false;
}

}  // namespace gi::ml

namespace gi::ml {

namespace {

// The per-vertex attributes every participating layer has (Scalarm or
// Point3m), in scene vertex order: what earlier filters left on the mesh.
std::vector<VertexAttribute> readAttributes(const BridgeScene& b) {
  std::vector<VertexAttribute> out;
  if (b.parts.empty()) return out;
  size_t nv = 0;
  for (const LayerPart& p : b.parts) nv += p.vertexCount;
  auto collect = [&](auto tag, int components) {
    using T = decltype(tag);
    std::vector<std::string> names;
    vcg::tri::Allocator<CMeshO>::GetAllPerVertexAttribute<T>(b.parts[0].mm->cm, names);
    for (const std::string& name : names) {
      VertexAttribute a{name, components, std::vector<float>(nv * size_t(components), 0.f)};
      bool everywhere = true;
      for (const LayerPart& p : b.parts) {
        CMeshO& m = p.mm->cm;
        // Of type T exactly: vcg finds an attribute by its size only (an int read as a float).
        if (clashes<T>(m, name)) { everywhere = false; break; }
        auto h = vcg::tri::Allocator<CMeshO>::FindPerVertexAttribute<T>(m, name);
        if (!vcg::tri::Allocator<CMeshO>::IsValidHandle<T>(m, h)) { everywhere = false; break; }
        for (size_t i = 0; i < m.vert.size(); ++i) {
          if (p.sceneVertex[i] < 0) continue;
          float* x = &a.values[size_t(p.sceneVertex[i]) * size_t(components)];
          if constexpr (std::is_same_v<T, Point3m>) x[0] = h[i][0], x[1] = h[i][1], x[2] = h[i][2];
          else x[0] = float(h[i]);
        }
      }
      if (everywhere) out.push_back(std::move(a));
    }
  };
  collect(Scalarm(), 1);
  collect(Point3m(), 3);
  // The vertex quality, where every layer has one, under the name the PLY
  // files give it: the error map compares it (gi::kQualityAttribute).
  bool quality = true;
  for (const LayerPart& p : b.parts) quality &= p.mm->hasDataMask(MeshModel::MM_VERTQUALITY);
  if (quality) {
    VertexAttribute q{kQualityAttribute, 1, std::vector<float>(nv, 0.f)};
    for (const LayerPart& p : b.parts)
      for (size_t i = 0; i < p.mm->cm.vert.size(); ++i)
        if (p.sceneVertex[i] >= 0) q.values[size_t(p.sceneVertex[i])] = float(p.mm->cm.vert[i].cQ());
    out.push_back(std::move(q));
  }
  return out;
}

ShotData toShotData(const Shotm& shot) {
  ShotData s;
  const Point3m vp = shot.GetViewPoint();
  const auto R = shot.Extrinsics.Rot();
  for (int i = 0; i < 3; ++i) {
    s.viewpoint[i] = vp[i];
    for (int j = 0; j < 3; ++j) s.rotation[i][j] = R[i][j];
  }
  s.focalMm = shot.Intrinsics.FocalMm;
  for (int k = 0; k < 2; ++k) {
    s.pixelSizeMm[k] = shot.Intrinsics.PixelSizeMm[k];
    s.centerPx[k] = shot.Intrinsics.CenterPx[k];
    s.viewportPx[k] = shot.Intrinsics.ViewportPx[k];
  }
  s.orthographic = shot.Intrinsics.cameraType == vcg::Camera<Scalarm>::ORTHO;
  return s;
}

Shotm toShotm(const ShotData& s) {
  Shotm shot;
  vcg::Matrix44<Scalarm> R;
  R.SetIdentity();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R[i][j] = Scalarm(s.rotation[i][j]);
  shot.Extrinsics.SetRot(R);
  shot.Extrinsics.SetTra(Point3m(Scalarm(s.viewpoint[0]), Scalarm(s.viewpoint[1]), Scalarm(s.viewpoint[2])));
  shot.Intrinsics.FocalMm = Scalarm(s.focalMm);
  for (int k = 0; k < 2; ++k) {
    shot.Intrinsics.PixelSizeMm[k] = Scalarm(s.pixelSizeMm[k]);
    shot.Intrinsics.CenterPx[k] = Scalarm(s.centerPx[k]);
    shot.Intrinsics.ViewportPx[k] = s.viewportPx[k];
  }
  shot.Intrinsics.cameraType = s.orthographic ? vcg::Camera<Scalarm>::ORTHO : vcg::Camera<Scalarm>::PERSPECTIVE;
  return shot;
}

}  // namespace

void addRasters(MeshDocument& md, const FilterResult& r) {
  for (const FilterImage& img : r.images) {
    const std::vector<uint8_t> rgb = toSrgb8(img.image, img.exposure);
    QImage q(img.image.width, img.image.height, QImage::Format_RGB888);
    for (int y = 0; y < img.image.height; ++y)
      std::memcpy(q.scanLine(y), &rgb[size_t(y) * size_t(img.image.width) * 3], size_t(img.image.width) * 3);
    RasterModel* rm = md.addNewRaster();
    rm->setLabel(QString::fromStdString(img.name));
    auto* plane = new compat::ImagePlane(QString::fromStdString(img.path.empty() ? img.name + ".png" : img.path),
                                         compat::ImagePlane::RGBA);
    plane->image = q.convertToFormat(QImage::Format_ARGB32);
    rm->addPlane(plane);
    rm->shot = toShotm(img.camera.toShot());
  }
}

namespace {
// Marks a layer a filter of ours made: a per-mesh attribute holding the
// result's name and the label MeshLab gave the layer (it lives as long as the
// layer in MeshLab's memory and is never saved with it).
struct ResultLayerMark {
  std::string result, label;
};
constexpr const char* kResultLayerMark = "gi_result_layer";

// The layer an earlier run made for this result, or null. Only a marked
// layer still under the label it was given: a layer of the user's under the
// same name (loaded, or made by another tool) and one of ours the user
// renamed (to keep it) are never touched.
MeshModel* earlierResultLayer(MeshDocument& md, const std::string& result) {
  for (MeshModel* m : compat::meshes(md)) {
    if (!vcg::tri::HasPerMeshAttribute(m->cm, kResultLayerMark)) continue;
    auto h = vcg::tri::Allocator<CMeshO>::FindPerMeshAttribute<ResultLayerMark>(m->cm, kResultLayerMark);
    if (vcg::tri::Allocator<CMeshO>::IsValidHandle(m->cm, h) && h().result == result &&
        h().label == m->label().toStdString())
      return m;
  }
  return nullptr;
}
}  // namespace

std::vector<std::string> addLayers(MeshDocument& md, const FilterResult& r) {
  std::vector<std::string> notes;
  for (const FilterLayer& L : r.layers) {
    // A re-run refills the layer it made before, in place (it may be the
    // current layer), rather than stacking "Photons(1)", "Photons(2)"...
    MeshModel* mm = earlierResultLayer(md, L.name);
    if (mm) {
      mm->cm.Clear();
      mm->cm.Tr.SetIdentity();  // positions are written in world coordinates
      notes.push_back("layer '" + mm->label().toStdString() + "' (an earlier run's " + L.name + ") refilled");
    } else {
      mm = compat::addMeshLayer(md, QString::fromStdString(L.name));
      auto h = vcg::tri::Allocator<CMeshO>::GetPerMeshAttribute<ResultLayerMark>(mm->cm, kResultLayerMark);
      h() = {L.name, mm->label().toStdString()};
    }
    CMeshO& m = mm->cm;
    const size_t nv = L.mesh.vertexCount();
    int mask = 0;
    if (!L.quality.empty()) mask |= MeshModel::MM_VERTQUALITY;
    if (!L.color.empty()) mask |= MeshModel::MM_VERTCOLOR;
    mm->updateDataMask(mask);
    vcg::tri::Allocator<CMeshO>::AddVertices(m, nv);
    for (size_t i = 0; i < nv; ++i) {
      CVertexO& v = m.vert[i];
      const glm::dvec3 p = L.mesh.toWorld(L.mesh.positions[i]);
      v.P() = Point3m(Scalarm(p.x), Scalarm(p.y), Scalarm(p.z));
      if (!L.normals.empty()) v.N() = Point3m(L.normals[i].x, L.normals[i].y, L.normals[i].z);
      if (!L.quality.empty()) v.Q() = L.quality[i];
      if (!L.color.empty()) v.C() = vcg::Color4b(L.color[i].r, L.color[i].g, L.color[i].b, 255);
    }
    if (!L.mesh.triangles.empty()) {
      vcg::tri::Allocator<CMeshO>::AddFaces(m, L.mesh.triangles.size());
      for (size_t f = 0; f < L.mesh.triangles.size(); ++f)
        for (int k = 0; k < 3; ++k) m.face[f].V(k) = &m.vert[L.mesh.triangles[f][k]];
      vcg::tri::UpdateNormal<CMeshO>::PerFaceNormalized(m);
      if (L.normals.empty()) vcg::tri::UpdateNormal<CMeshO>::PerVertexAngleWeighted(m);
    }
    vcg::tri::UpdateBounding<CMeshO>::Box(m);
  }
  return notes;
}

FilterInput gatherInput(MeshDocument& md, const RichParameterList& par, FilterKind kind, BridgeScene& b) {
  FilterInput in;
  in.values = readParams(par, filterSpecs(kind));
  const SceneExtent extent =
      in.values.has("scene_extent") ? kSceneExtents.get(in.values, "scene_extent") : SceneExtent::CurrentLayer;
  size_t faceless = 0;
  b = toScene(participatingLayers(md, extent, &faceless));
  if (faceless)
    b.notes.push_back(std::to_string(faceless) + " visible layer" + (faceless > 1 ? "s" : "") +
                      " without faces (point clouds) left out and unchanged");
  in.scene = std::move(b.scene);  // the bridge keeps the layers' indexing, the engine the geometry
  in.attrs = b.attrs;
  for (const LayerPart& p : b.parts) in.layers.push_back({p.mm->label().toStdString(), p.faceOffset, p.faceCount});
  // MeshLab's face numbers, where deleted faces make them differ from the
  // scene's: each layer's faces after the faces of the layers before it,
  // deleted ones counted (face_index named the wrong face; an outside audit).
  bool deleted = false;
  for (const LayerPart& p : b.parts) deleted |= p.mm->cm.face.size() != p.faceCount;
  if (deleted) {
    uint64_t base = 0;
    for (const LayerPart& p : b.parts) {
      const CMeshO& m = p.mm->cm;
      for (size_t i = 0; i < m.face.size(); ++i)
        if (!m.face[i].IsD()) in.faceNumbers.push_back(base + i);
      base += m.face.size();
    }
  }
  in.attributes = readAttributes(b);
  in.readVertexFile = io::readVertexFile;  // a reference file a parameter names
  if (md.mm() && md.mm()->cm.shot.IsValid()) {
    // The layer's camera moves with its unfrozen matrix, as freezing it
    // would move it (MeshLab's Freeze applies the matrix to the shot).
    Shotm shot = md.mm()->cm.shot;
    if (!LayerMatrix(*md.mm()).identity) shot.ApplyRigidTransformation(md.mm()->cm.Tr);
    in.layerCamera = toShotData(shot);
  }
  return in;
}

}  // namespace gi::ml
