// The refined mesh back into MeshLab: each layer's faces are replaced by its
// part of the refined mesh, new vertices are appended (old vertices and their
// attributes stay), and the bridge is re-indexed as toScene would index the
// new layers, so the write-back works unchanged.
#include "meshlab_bridge.h"  // first: MeshLab's mesh types before vcg's algorithms

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <typeinfo>

#include <vcg/complex/algorithms/update/bounding.h>
#include <vcg/complex/algorithms/update/normal.h>
#include <vcg/complex/algorithms/update/topology.h>

#include "gi/color.h"

namespace gi::ml {

namespace {

vcg::Color4b mixColors(const vcg::Color4b& a, const vcg::Color4b& b) {
  // In linear light, as the engine mixes colours.
  const glm::vec3 lin = 0.5f * (srgb8ToLinear(a[0], a[1], a[2]) + srgb8ToLinear(b[0], b[1], b[2]));
  const Rgb8 c = displayMap(lin, 1.f);
  return vcg::Color4b(c.r, c.g, c.b, (a[3] + b[3] + 1) / 2);
}

// A point's barycentric coordinates in the triangle (a, b, c) (of its
// plane); a degenerate triangle gives its first corner.
glm::dvec3 barycentric(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const glm::dvec3 e0 = b - a, e1 = c - a, e2 = p - a;
  const double d00 = glm::dot(e0, e0), d01 = glm::dot(e0, e1), d11 = glm::dot(e1, e1);
  const double d20 = glm::dot(e2, e0), d21 = glm::dot(e2, e1), den = d00 * d11 - d01 * d01;
  if (!(den > 0.0)) return {1.0, 0.0, 0.0};
  const double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
  return {1.0 - v - w, v, w};
}

glm::dvec3 position(const CVertexO& v) { return {double(v.cP()[0]), double(v.cP()[1]), double(v.cP()[2])}; }

// A per-element attribute of the layer: the two MeshLab's filters write and
// mix (a float, a point), or any other, which is copied.
enum class AttrKind { Scalar, Point, Other };
AttrKind kindOf(const vcg::PointerToAttribute& a) {
  if (a._padding != 0) return AttrKind::Other;
  if (a._type == typeid(Scalarm) && a._sizeof == sizeof(Scalarm)) return AttrKind::Scalar;
  if (a._type == typeid(Point3m) && a._sizeof == sizeof(Point3m)) return AttrKind::Point;
  return AttrKind::Other;
}

// A new vertex halfway between cm.vert[ia] and cm.vert[ib] (at index i):
// its texture coordinates and the layer's own per-vertex attributes (an
// outside audit: they were left as whatever memory held, or 0).
void mixVertexData(MeshModel& mm, size_t i, size_t ia, size_t ib) {
  CMeshO& cm = mm.cm;
  CVertexO& x = cm.vert[i];
  const CVertexO &a = cm.vert[ia], &b = cm.vert[ib];
  if (mm.hasDataMask(MeshModel::MM_VERTTEXCOORD)) {
    x.T().U() = (a.cT().U() + b.cT().U()) * Scalarm(0.5);
    x.T().V() = (a.cT().V() + b.cT().V()) * Scalarm(0.5);
    x.T().N() = a.cT().N();
  }
  if (a.IsS() && b.IsS()) x.SetS();
  for (const auto& attr : cm.vert_attr) {
    auto* h = static_cast<vcg::SimpleTempDataBase*>(attr._handle);
    switch (kindOf(attr)) {
      case AttrKind::Scalar:
        *static_cast<Scalarm*>(h->At(i)) =
            (*static_cast<const Scalarm*>(h->At(ia)) + *static_cast<const Scalarm*>(h->At(ib))) * Scalarm(0.5);
        break;
      case AttrKind::Point:
        *static_cast<Point3m*>(h->At(i)) =
            (*static_cast<const Point3m*>(h->At(ia)) + *static_cast<const Point3m*>(h->At(ib))) * Scalarm(0.5);
        break;
      case AttrKind::Other: h->CopyValue(i, ia, h); break;
    }
  }
}

// What a layer's face held before refinement replaced it: its corners (cm
// vertex indices) and per-corner (wedge) texture coordinates, normals and
// colours, interpolated onto the new faces cut from it.
struct OldFace {
  vcg::Color4b c;
  Scalarm q;
  bool sel;
  size_t v[3];
  CFaceO::TexCoordType wt[3];
  Point3m wn[3];
  vcg::Color4b wc[3];
};

}  // namespace

RefinedOrder replaceWithRefined(BridgeScene& b, const RefinedMesh& m) {
  const size_t nv = m.scene.vertexCount(), nf = m.scene.faceCount();
  size_t inputVertices = 0;
  for (const LayerPart& p : b.parts) inputVertices += p.vertexCount;
  if (m.inputVertices != inputVertices)
    throw std::logic_error("refined mesh does not match the layers");
  // Which part each refined vertex and face belongs to (parts share no vertex).
  std::vector<int> partOfVertex(nv, -1);
  for (size_t p = 0; p < b.parts.size(); ++p)
    for (size_t v = b.parts[p].vertexOffset; v < b.parts[p].vertexOffset + b.parts[p].vertexCount; ++v)
      partOfVertex[v] = int(p);
  for (size_t v = m.inputVertices; v < nv; ++v) partOfVertex[v] = partOfVertex[m.vertexParents[v].x];
  std::vector<int> partOfFace(nf, -1);
  for (size_t f = 0; f < nf; ++f)
    for (size_t p = 0; p < b.parts.size(); ++p)
      if (m.sourceFace[f] >= b.parts[p].faceOffset && m.sourceFace[f] < b.parts[p].faceOffset + b.parts[p].faceCount)
        partOfFace[f] = int(p);

  std::vector<uint32_t> vertexOrder, faceOrder;  // new scene index -> refined index
  vertexOrder.reserve(nv);
  faceOrder.reserve(nf);
  for (size_t p = 0; p < b.parts.size(); ++p) {
    LayerPart& part = b.parts[p];
    CMeshO& cm = part.mm->cm;
    const bool vc = part.mm->hasDataMask(MeshModel::MM_VERTCOLOR), vq = part.mm->hasDataMask(MeshModel::MM_VERTQUALITY);
    const bool fc = part.mm->hasDataMask(MeshModel::MM_FACECOLOR), fq = part.mm->hasDataMask(MeshModel::MM_FACEQUALITY);
    // The layer's faces in scene order (toScene skipped the deleted ones).
    std::vector<size_t> cmFace;
    for (size_t i = 0; i < cm.face.size(); ++i)
      if (!cm.face[i].IsD()) cmFace.push_back(i);
    const bool wt = part.mm->hasDataMask(MeshModel::MM_WEDGTEXCOORD);
    const bool wn = part.mm->hasDataMask(MeshModel::MM_WEDGNORMAL), wc = part.mm->hasDataMask(MeshModel::MM_WEDGCOLOR);
    std::vector<OldFace> old(cmFace.size());
    for (size_t k = 0; k < cmFace.size(); ++k) {
      const CFaceO& f = cm.face[cmFace[k]];
      OldFace& o = old[k];
      o.c = fc ? f.cC() : vcg::Color4b(vcg::Color4b::White);
      o.q = fq ? f.cQ() : Scalarm(0);
      o.sel = f.IsS();
      for (int j = 0; j < 3; ++j) {
        o.v[j] = size_t(vcg::tri::Index(cm, f.cV(j)));
        if (wt) o.wt[j] = f.cWT(j);
        if (wn) o.wn[j] = f.cWN(j);
        if (wc) o.wc[j] = f.cWC(j);
      }
    }
    // Scene vertex -> cm vertex index: the old ones, then the new ones appended.
    std::vector<int64_t> cmVertex(nv, -1);
    const size_t vOffset = vertexOrder.size();
    for (size_t i = 0; i < cm.vert.size(); ++i)
      if (part.sceneVertex[i] >= 0) {
        cmVertex[size_t(part.sceneVertex[i])] = int64_t(i);
        vertexOrder.push_back(uint32_t(part.sceneVertex[i]));
      }
    std::vector<uint32_t> added;
    for (size_t v = m.inputVertices; v < nv; ++v)
      if (partOfVertex[v] == int(p)) added.push_back(uint32_t(v));
    if (!added.empty()) {
      const size_t first = cm.vert.size();
      vcg::tri::Allocator<CMeshO>::AddVertices(cm, added.size());
      for (size_t k = 0; k < added.size(); ++k) {
        const uint32_t v = added[k];
        cmVertex[v] = int64_t(first + k);
        CVertexO& x = cm.vert[first + k];
        const CVertexO& a = cm.vert[size_t(cmVertex[m.vertexParents[v].x])];
        const CVertexO& c = cm.vert[size_t(cmVertex[m.vertexParents[v].y])];
        x.P() = (a.cP() + c.cP()) * Scalarm(0.5);  // the layer's own coordinates: exact midpoints
        Point3m n = a.cN() + c.cN();
        x.N() = n.Norm() > 0 ? n.Normalize() : a.cN();
        if (vc) x.C() = mixColors(a.cC(), c.cC());
        if (vq) x.Q() = (a.cQ() + c.cQ()) * Scalarm(0.5);
        mixVertexData(*part.mm, first + k, size_t(cmVertex[m.vertexParents[v].x]), size_t(cmVertex[m.vertexParents[v].y]));
        vertexOrder.push_back(v);
      }
    }
    // New faces in refined order; the old ones deleted and compacted away.
    std::vector<uint32_t> mine;
    for (size_t f = 0; f < nf; ++f)
      if (partOfFace[f] == int(p)) mine.push_back(uint32_t(f));
    for (size_t i : cmFace) vcg::tri::Allocator<CMeshO>::DeleteFace(cm, cm.face[i]);
    const size_t firstFace = cm.face.size();
    vcg::tri::Allocator<CMeshO>::AddFaces(cm, mine.size());
    const size_t fOffset = faceOrder.size();
    for (size_t k = 0; k < mine.size(); ++k) {
      const uint32_t f = mine[k];
      CFaceO& face = cm.face[firstFace + k];
      for (int j = 0; j < 3; ++j) face.V(j) = &cm.vert[size_t(cmVertex[m.scene.triangles[f][j]])];
      const size_t src = m.sourceFace[f] - part.faceOffset;
      const OldFace& d = old[src];
      if (fc) face.C() = d.c;
      if (fq) face.Q() = d.q;
      if (d.sel) face.SetS(); else face.ClearS();
      if (wt || wn || wc) {
        // Each corner's per-wedge values at its place in the source face
        // (the refined faces lie in it); they were left at a default
        // ((0.5, 0.5) texture coordinates on every face; an outside audit).
        const glm::dvec3 pa = position(cm.vert[d.v[0]]), pb = position(cm.vert[d.v[1]]), pc = position(cm.vert[d.v[2]]);
        for (int j = 0; j < 3; ++j) {
          const glm::dvec3 w = barycentric(position(*face.V(j)), pa, pb, pc);
          const Scalarm w0 = Scalarm(w.x), w1 = Scalarm(w.y), w2 = Scalarm(w.z);
          if (wt) {
            face.WT(j).U() = d.wt[0].U() * w0 + d.wt[1].U() * w1 + d.wt[2].U() * w2;
            face.WT(j).V() = d.wt[0].V() * w0 + d.wt[1].V() * w1 + d.wt[2].V() * w2;
            face.WT(j).N() = d.wt[0].N();
          }
          if (wn) {
            Point3m n = d.wn[0] * w0 + d.wn[1] * w1 + d.wn[2] * w2;
            face.WN(j) = n.Norm() > 0 ? n.Normalize() : d.wn[0];
          }
          if (wc)
            for (int ch = 0; ch < 4; ++ch)
              face.WC(j)[ch] = (unsigned char)std::lround(
                  std::clamp(double(d.wc[0][ch]) * w.x + double(d.wc[1][ch]) * w.y + double(d.wc[2][ch]) * w.z, 0.0, 255.0));
        }
      }
      // The layer's own per-face attributes, from the source face.
      for (const auto& attr : cm.face_attr) {
        auto* h = static_cast<vcg::SimpleTempDataBase*>(attr._handle);
        h->CopyValue(firstFace + k, cmFace[src], h);
      }
      faceOrder.push_back(f);
    }
    vcg::tri::Allocator<CMeshO>::CompactFaceVector(cm);
    if (part.mm->hasDataMask(MeshModel::MM_FACEFACETOPO)) vcg::tri::UpdateTopology<CMeshO>::FaceFace(cm);
    if (part.mm->hasDataMask(MeshModel::MM_VERTFACETOPO)) vcg::tri::UpdateTopology<CMeshO>::VertexFace(cm);
    vcg::tri::UpdateNormal<CMeshO>::PerFaceNormalized(cm);
    vcg::tri::UpdateBounding<CMeshO>::Box(cm);
    // The part as toScene would see the new layer.
    part.sceneVertex.assign(cm.vert.size(), -1);
    for (size_t i = 0; i < cm.vert.size(); ++i)
      if (!cm.vert[i].IsD()) part.sceneVertex[i] = -2;  // filled below
    size_t next = vOffset;
    for (size_t i = 0; i < cm.vert.size(); ++i)
      if (part.sceneVertex[i] == -2) part.sceneVertex[i] = int(next++);
    part.vertexOffset = vOffset;
    part.vertexCount = next - vOffset;
    part.faceOffset = fOffset;
    part.faceCount = mine.size();
  }
  if (vertexOrder.size() != nv || faceOrder.size() != nf) throw std::logic_error("refined mesh not covered by the layers");

  // The layers' old attributes no longer match: what toScene would read now is in the layers.
  b.scene = Scene();
  b.attrs = MeshAttributes();
  return {std::move(vertexOrder), std::move(faceOrder)};
}

}  // namespace gi::ml
