#include "meshlab_bridge.h"

#include <cmath>
#include <memory>
#include <utility>
#include <stdexcept>

#include <vcg/complex/algorithms/update/color.h>

namespace gi::ml {

std::vector<MeshModel*> participatingLayers(MeshDocument& md, int sceneExtent) {
  std::vector<MeshModel*> out;
  if (sceneExtent == 1) {
    for (MeshModel* m : md.meshList)
      if (m && m->isVisible()) out.push_back(m);
  } else if (md.mm()) {
    out.push_back(md.mm());
  }
  if (out.empty()) throw std::invalid_argument(sceneExtent == 1 ? "no visible layer to work on" : "no current layer to work on");
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
    const bool vc = mm->hasDataMask(MeshModel::MM_VERTCOLOR);
    const bool fc = mm->hasDataMask(MeshModel::MM_FACECOLOR);
    const bool fq = mm->hasDataMask(MeshModel::MM_FACEQUALITY);
    for (size_t i = 0; i < m.vert.size(); ++i) {
      const CVertexO& v = m.vert[i];
      if (v.IsD()) continue;
      part.sceneVertex[i] = int(pts.size());
      pts.emplace_back(v.cP()[0], v.cP()[1], v.cP()[2]);
      if (anyVertColor) {
        // Layers without vertex colours count as white-less grey: 188 = 0.5 linear.
        b.attrs.vertexColor.push_back(vc ? glm::u8vec3(v.cC()[0], v.cC()[1], v.cC()[2]) : glm::u8vec3(188));
      }
    }
    for (size_t i = 0; i < m.face.size(); ++i) {
      const CFaceO& f = m.face[i];
      if (f.IsD()) continue;
      glm::uvec3 t;
      for (int k = 0; k < 3; ++k) t[k] = uint32_t(part.sceneVertex[vcg::tri::Index(m, f.cV(k))]);
      tris.push_back(t);
      if (anyFaceColor) b.attrs.faceColor.push_back(fc ? glm::u8vec3(f.cC()[0], f.cC()[1], f.cC()[2]) : glm::u8vec3(188));
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
  b.scene = Scene::fromAbsolute(pts, std::move(tris));
  return b;
}

void addParams(RichParameterList& out, const std::vector<ParamSpec>& specs, double diagonal) {
  const double d = diagonal > 0 ? diagonal : 1.0;
  for (const ParamSpec& s : specs) {
    const QString name = QString::fromStdString(s.name), label = QString::fromStdString(s.label);
    // The script name in the help: .mlx writers and `meshlabserver -d` readers need it.
    const QString help = QString::fromStdString(s.help + " [.mlx name: " + s.name + "]");
    auto toColor = [](glm::vec3 c) { return QColor(int(std::lround(c.r * 255)), int(std::lround(c.g * 255)), int(std::lround(c.b * 255))); };
    switch (s.type) {
      case ParamType::Bool: out.addParam(RichBool(name, s.def != 0.0, label, help)); break;
      case ParamType::Int: out.addParam(RichInt(name, int(s.def), label, help)); break;
      case ParamType::Float: out.addParam(RichFloat(name, float(s.def), label, help)); break;
      case ParamType::Distance:
        out.addParam(RichAbsPerc(name, float(s.def * d), 0.f, float((s.max > 0 ? s.max : 1.0) * d), label, help));
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
        out.addParam(RichPoint3f(name, vcg::Point3f(s.defVec.x, s.defVec.y, s.defVec.z), label, help));
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
        v.set(s.name, glm::vec3(c.red() / 255.f, c.green() / 255.f, c.blue() / 255.f));
        break;
      }
      case ParamType::Direction:
      case ParamType::Point: {
        vcg::Point3f p = in.getPoint3f(n);
        v.set(s.name, glm::vec3(p[0], p[1], p[2]));
        break;
      }
      case ParamType::String: v.set(s.name, in.getString(n).toStdString()); break;
    }
  }
  return v;
}

double documentDiagonal(MeshDocument& md) {
  vcg::Box3<MESHLAB_SCALAR> box;
  for (MeshModel* m : md.meshList)
    if (m && (m == md.mm() || m->isVisible())) box.Add(m->cm.bbox);
  const double d = box.IsNull() ? 1.0 : double(box.Diag());
  return d > 0 && std::isfinite(d) ? d : 1.0;
}

size_t writeVertexResults(BridgeScene& b, const std::vector<float>& quality, const std::vector<Rgb8>& colors) {
  size_t bad = 0;
  for (LayerPart& p : b.parts) {
    int mask = int(MeshModel::MM_VERTQUALITY) | (colors.empty() ? 0 : int(MeshModel::MM_VERTCOLOR));
    p.mm->updateDataMask(mask);
    CMeshO& m = p.mm->cm;
    for (size_t i = 0; i < m.vert.size(); ++i) {
      const int s = p.sceneVertex[i];
      if (s < 0) continue;
      float q = quality[size_t(s)];
      if (!std::isfinite(q)) { q = 0.f; ++bad; }
      m.vert[i].Q() = q;
      if (!colors.empty()) {
        const Rgb8 c = colors[size_t(s)];
        m.vert[i].C() = vcg::Color4b(c.r, c.g, c.b, 255);
      }
    }
  }
  return bad;
}

size_t writeFaceResults(BridgeScene& b, const std::vector<float>& quality, const std::vector<Rgb8>& colors) {
  size_t bad = 0;
  for (LayerPart& p : b.parts) {
    p.mm->updateDataMask(int(MeshModel::MM_FACEQUALITY) | int(MeshModel::MM_FACECOLOR));
    CMeshO& m = p.mm->cm;
    size_t k = p.faceOffset;
    for (size_t i = 0; i < m.face.size(); ++i) {
      if (m.face[i].IsD()) continue;
      float q = quality[k];
      if (!std::isfinite(q)) { q = 0.f; ++bad; }
      m.face[i].Q() = q;
      const Rgb8 c = colors[k];
      m.face[i].C() = vcg::Color4b(c.r, c.g, c.b, 255);
      ++k;
    }
  }
  return bad;
}

void writeVertexVectorAttribute(BridgeScene& b, const std::string& name, const std::vector<glm::vec3>& v, bool alsoNormals) {
  for (LayerPart& p : b.parts) {
    CMeshO& m = p.mm->cm;
    auto h = vcg::tri::Allocator<CMeshO>::GetPerVertexAttribute<Point3m>(m, name);
    if (alsoNormals) p.mm->updateDataMask(MeshModel::MM_VERTNORMAL);
    for (size_t i = 0; i < m.vert.size(); ++i) {
      const int s = p.sceneVertex[i];
      if (s < 0) continue;
      glm::vec3 x = v[size_t(s)];
      if (!std::isfinite(x.x) || !std::isfinite(x.y) || !std::isfinite(x.z)) x = glm::vec3(0.f);
      h[m.vert[i]] = Point3m(x.x, x.y, x.z);
      if (alsoNormals) m.vert[i].N() = Point3m(x.x, x.y, x.z);
    }
  }
}

void writeVertexScalarAttribute(BridgeScene& b, const std::string& name, const std::vector<float>& v) {
  for (LayerPart& p : b.parts) {
    CMeshO& m = p.mm->cm;
    auto h = vcg::tri::Allocator<CMeshO>::GetPerVertexAttribute<Scalarm>(m, name);
    for (size_t i = 0; i < m.vert.size(); ++i) {
      const int s = p.sceneVertex[i];
      if (s < 0) continue;
      const float x = v[size_t(s)];
      h[m.vert[i]] = std::isfinite(x) ? x : 0.f;
    }
  }
}

void multiplyVertexColors(BridgeScene& b, const std::vector<float>& factor) {
  for (LayerPart& p : b.parts) {
    const bool had = p.mm->hasDataMask(MeshModel::MM_VERTCOLOR);
    p.mm->updateDataMask(MeshModel::MM_VERTCOLOR);
    CMeshO& m = p.mm->cm;
    for (size_t i = 0; i < m.vert.size(); ++i) {
      const int s = p.sceneVertex[i];
      if (s < 0) continue;
      float f = factor[size_t(s)];
      if (!std::isfinite(f)) f = 0.f;
      vcg::Color4b c = had ? m.vert[i].C() : vcg::Color4b(255, 255, 255, 255);
      // Scale in linear light, then re-encode.
      glm::vec3 lin = srgb8ToLinear(c[0], c[1], c[2]) * f;
      Rgb8 o = displayMap(lin, 1.f);
      m.vert[i].C() = vcg::Color4b(o.r, o.g, o.b, c[3]);
    }
  }
}

ProgressFn progressFrom(vcg::CallBackPos* cb) {
  if (!cb) return nullptr;
  // meshlabserver prints every call's message: pass on only new stages and
  // steps of 5%, which is also all a progress bar needs.
  auto last = std::make_shared<std::pair<int, std::string>>(-100, "");
  return [cb, last](int pct, const std::string& stage) {
    if (stage == last->second && pct < last->first + 5 && pct < 100) return true;
    *last = {pct, stage};
    cb(pct, stage.c_str());
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

PreparedRun prepare(MeshDocument& md, const RichParameterList& par, const std::vector<ParamSpec>& specs,
                    bool withEmitters) {
  PreparedRun r;
  r.values = readParams(par, specs);
  const double diag = documentDiagonal(md);
  if (auto err = validate(specs, r.values, diag)) throw std::invalid_argument(*err);
  const int extent = r.values.has("scene_extent") ? r.values.getInt("scene_extent") : 0;
  r.bridge = toScene(participatingLayers(md, extent));
  if (r.values.has("reflectance_source"))
    if (auto err = applySceneConventions(r.bridge.scene, r.bridge.attrs, r.values, withEmitters, &r.setupLog))
      throw std::invalid_argument(*err);
  if (r.values.has("mirror_layers")) {
    std::vector<LayerRange> layers;
    for (const LayerPart& p : r.bridge.parts) layers.push_back({p.mm->label().toStdString(), p.faceOffset, p.faceCount});
    std::string log;
    if (auto err = applyMaterials(r.bridge.scene, layers, r.values, &log)) throw std::invalid_argument(*err);
    r.setupLog += "; " + log;
  }
  r.report = analyzeScene(r.bridge.scene);
  if (r.report.usableFaces() == 0)
    throw std::invalid_argument("the mesh has no usable triangles (" + r.report.summary() + ")");
  return r;
}


}  // namespace gi::ml

#include "gi/direct.h"
#include "gi/output.h"

namespace gi::ml {
void writeRadiosity(PreparedRun& run, const std::vector<glm::vec3>& Bvertex, const std::vector<glm::vec3>& Bface,
                    bool faces, RunStats& stats) {
  VertexOutput out = radiometricOutput(run.bridge.scene, Bvertex, run.values.getFloat("exposure"));
  size_t bad = writeVertexResults(run.bridge, out.quality, out.displayColors());
  if (faces) {
    VertexOutput f;
    f.rgb = Bface;
    f.exposure = out.exposure;
    for (const auto& b : Bface) f.quality.push_back(luminance(b));
    bad += writeFaceResults(run.bridge, f.quality, f.displayColors());
  }
  stats.add("exposure", out.exposure);
  if (bad) stats.note(std::to_string(bad) + " non-finite values written as 0");
}

void writeRadiometry(PreparedRun& run, VertexRadiometry& r) { writeRadiosity(run, r.B, {}, false, r.stats); }
}  // namespace gi::ml
