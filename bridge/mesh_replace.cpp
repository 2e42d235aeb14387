// The refined mesh back into MeshLab: each layer's faces are replaced by its
// part of the refined mesh, new vertices are appended (old vertices and their
// attributes stay), and the bridge is re-indexed as toScene would index the
// new layers, so the ordinary write-back functions work unchanged.
#include "meshlab_bridge.h"  // first: MeshLab's mesh types before vcg's algorithms

#include <algorithm>
#include <stdexcept>

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

}  // namespace

void replaceWithRefined(BridgeScene& b, const RefinedMesh& m, std::vector<glm::vec3>& Bvertex,
                        std::vector<glm::vec3>& Bface) {
  const size_t nv = m.scene.vertexCount(), nf = m.scene.faceCount();
  if (m.inputVertices != b.scene.vertexCount() || Bvertex.size() != nv || Bface.size() != nf)
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
    struct FaceData { vcg::Color4b c; Scalarm q; bool sel; };
    std::vector<FaceData> old(cmFace.size());
    for (size_t k = 0; k < cmFace.size(); ++k) {
      const CFaceO& f = cm.face[cmFace[k]];
      old[k] = {fc ? f.cC() : vcg::Color4b(vcg::Color4b::White), fq ? f.cQ() : Scalarm(0), f.IsS()};
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
      const FaceData& d = old[m.sourceFace[f] - part.faceOffset];
      if (fc) face.C() = d.c;
      if (fq) face.Q() = d.q;
      if (d.sel) face.SetS(); else face.ClearS();
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

  // The scene, attributes and results in the new order.
  std::vector<uint32_t> newIndex(nv);
  for (size_t i = 0; i < nv; ++i) newIndex[vertexOrder[i]] = uint32_t(i);
  const MeshAttributes refinedAttrs = refineAttributes(b.attrs, m);
  Scene s;
  s.origin = m.scene.origin;
  s.unit = m.scene.unit;
  MeshAttributes a;
  std::vector<glm::vec3> Bv(nv), Bf(nf);
  for (size_t i = 0; i < nv; ++i) {
    s.positions.push_back(m.scene.positions[vertexOrder[i]]);
    if (!m.scene.vertexNormals.empty()) s.vertexNormals.push_back(m.scene.vertexNormals[vertexOrder[i]]);
    if (!refinedAttrs.vertexColor.empty()) a.vertexColor.push_back(refinedAttrs.vertexColor[vertexOrder[i]]);
    Bv[i] = Bvertex[vertexOrder[i]];
  }
  for (size_t i = 0; i < nf; ++i) {
    const uint32_t f = faceOrder[i];
    const glm::uvec3 t = m.scene.triangles[f];
    s.triangles.push_back({newIndex[t.x], newIndex[t.y], newIndex[t.z]});
    if (!m.scene.rho.empty()) s.rho.push_back(m.scene.rho[f]);
    if (!m.scene.emission.empty()) s.emission.push_back(m.scene.emission[f]);
    if (!m.scene.material.empty()) s.material.push_back(m.scene.material[f]);
    if (!m.scene.ior.empty()) s.ior.push_back(m.scene.ior[f]);
    if (!refinedAttrs.faceColor.empty()) a.faceColor.push_back(refinedAttrs.faceColor[f]);
    if (!refinedAttrs.faceQuality.empty()) a.faceQuality.push_back(refinedAttrs.faceQuality[f]);
    if (!refinedAttrs.faceSelected.empty()) a.faceSelected.push_back(refinedAttrs.faceSelected[f]);
    Bf[i] = Bface[f];
  }
  b.scene = std::move(s);
  b.attrs = std::move(a);
  Bvertex.swap(Bv);
  Bface.swap(Bf);
}

}  // namespace gi::ml
