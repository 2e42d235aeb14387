// The path-traced reference on a random sample of the vertices
// (traced_vertices): the sample is deterministic and uniform, the traced
// vertices get exactly the values of a full run (random numbers keyed by the
// vertex), the others 0 with traced = 0, and the count is reported. And on
// the selected vertices (traced_selected), the selection read from a PLY's
// vertex flags as MeshLab saves it.
#include <gtest/gtest.h>

#include "gi/vertex_graph.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "gi/filter_run.h"
#include "gi/pathtrace.h"
#include "gi/scenes.h"
#include "gi/vertex_part.h"
#include "mesh_io.h"

using namespace gi;

// count of n marked, the same for the same seed, another set for another seed.
// Uniform: over 2000 draws of 100 of 1000 vertices each vertex is drawn 200
// times on average (binomial, sd sqrt(2000 x 0.1 x 0.9) = 13.4); the
// counts of the first and second halves of the vertices are each 100,000 on
// average with sd about 300: within 1,500 (5 sd).
TEST(ReferenceSubset, RandomSubsetIsDeterministicAndUniform) {
  const size_t n = 1000, count = 100;
  const auto a = randomVertexSubset(n, count, 7), b = randomVertexSubset(n, count, 7), c = randomVertexSubset(n, count, 8);
  size_t marked = 0, same = 0;
  for (size_t v = 0; v < n; ++v) {
    marked += (*a)[v];
    same += (*a)[v] && (*c)[v];
  }
  EXPECT_EQ(marked, count);
  EXPECT_EQ(*a, *b);
  EXPECT_LT(same, count / 2);  // two independent samples share about 10
  size_t low = 0, high = 0;
  for (uint32_t seed = 0; seed < 2000; ++seed) {
    const auto m = randomVertexSubset(n, count, seed);
    for (size_t v = 0; v < n; ++v) (v < n / 2 ? low : high) += (*m)[v];
  }
  EXPECT_NEAR(double(low), 100000.0, 1500.0);
  EXPECT_NEAR(double(high), 100000.0, 1500.0);
  const auto all = randomVertexSubset(n, n + 5, 1);
  for (uint8_t x : *all) EXPECT_EQ(x, 1);
}

// 40 of the Cornell box's vertices: bit-identical to the full run there, 0
// elsewhere; 40 traced (every vertex of the box is on a diffuse face); the
// log says how many have error bars of their own paths alone.
TEST(ReferenceSubset, TracedVerticesMatchTheFullRun) {
  const auto sf = scenes::cornellBox(150.0);
  const Scene& s = sf.scene;
  auto caster = makeEmbreeCaster(s);
  PathTraceOptions o;
  o.samplesPerVertex = 16;
  const PathTraceResult full = pathTrace(s, *caster, o);
  o.tracedVertices = 40;
  o.tracedVertexSeed = 3;
  const PathTraceResult part = pathTrace(s, *caster, o);
  const auto mask = randomVertexSubset(s.vertexCount(), 40, 3);
  const VertexGraph graph = VertexGraph::build(s);
  size_t traced = 0, isolated = 0;
  for (size_t v = 0; v < s.vertexCount(); ++v) {
    ASSERT_EQ(part.traced[v], (*mask)[v]) << v;
    traced += part.traced[v];
    if (part.traced[v]) {
      EXPECT_EQ(part.B[v], full.B[v]) << v;
      // Without another traced vertex within 4 rings its error bar is its
      // own paths', at most the full run's (the larger of its own and its pool's).
      std::vector<uint32_t> ring{uint32_t(v)};
      for (int level = 0, begin = 0; level < 4; ++level) {
        const int end = int(ring.size());
        for (int a = begin; a < end; ++a)
          for (uint32_t k = graph.offset[ring[size_t(a)]]; k < graph.offset[ring[size_t(a)] + 1]; ++k)
            if (std::find(ring.begin(), ring.end(), graph.nbr[k]) == ring.end()) ring.push_back(graph.nbr[k]);
        begin = end;
      }
      bool alone = true;
      for (uint32_t j : ring) alone = alone && (j == v || !(*mask)[j]);
      if (alone) {
        EXPECT_LE(part.stdError[v], full.stdError[v]) << v;
      }
      isolated += alone;
    } else {
      EXPECT_EQ(part.B[v], glm::vec3(0.f)) << v;
      EXPECT_EQ(part.samples[v], 0) << v;
    }
  }
  EXPECT_EQ(traced, 40u);
  EXPECT_EQ(part.stats.get("traced_vertices"), 40.0);
  EXPECT_GT(isolated, 0u);
  EXPECT_NE(part.stats.line("reference").find(std::to_string(isolated) + " traced vertices have no other traced vertex within 4 rings"),
            std::string::npos)
      << part.stats.line("reference");
  EXPECT_EQ(full.stats.get("traced_vertices"), double(s.vertexCount()));
}

// 'GI: Path-Traced Reference' with traced_selected, as MeshLab and the CLI run
// it: the selected vertices get exactly the full run's values (keyed by the
// vertex), the others 0 and ReferenceTraced 0; no selection is an error.
TEST(ReferenceSubset, TracedSelectedTracesOnlyTheSelection) {
  const auto sf = scenes::cornellBox(150.0);
  auto run = [&](bool selected, const std::vector<uint8_t>& sel) {
    FilterInput in;
    in.scene = sf.scene;
    in.attrs = sf.attrs;
    in.attrs.vertexSelected = sel;
    in.layers.push_back({"mesh", 0, sf.scene.faceCount()});
    const auto specs = filterSpecs(FilterKind::PathTracedReference);
    in.values = defaultValues(specs, analyzeScene(in.scene).diagonal);
    in.values.set("emitter_source", int(kEmitterSources.index(EmitterSource::QualityAbove)));
    in.values.set("samples_per_vertex", 16);
    in.values.set("traced_selected", selected);
    return runFilter(FilterKind::PathTracedReference, in);
  };
  const size_t nv = sf.scene.vertexCount();
  std::vector<uint8_t> sel(nv, 0);
  for (size_t v = 3; v < nv; v += 17) sel[v] = 1;
  const FilterResult full = run(false, {}), part = run(true, sel);
  const VertexAttribute* traced = part.attribute("ReferenceTraced");
  ASSERT_NE(traced, nullptr);
  size_t count = 0;
  for (size_t v = 0; v < nv; ++v) {
    ASSERT_EQ(traced->values[v], float(sel[v])) << v;
    count += sel[v];
    if (sel[v]) EXPECT_EQ(part.vertexQuality[v], full.vertexQuality[v]) << v;
    else EXPECT_EQ(part.attribute("Radiosity")->values[3 * v], 0.f) << v;
  }
  EXPECT_EQ(part.stats.get("traced_vertices"), double(count));
  for (const std::vector<uint8_t>& none : {std::vector<uint8_t>{}, std::vector<uint8_t>(nv, 0)}) {
    try {
      run(true, none);
      ADD_FAILURE() << "no selection was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("no vertex is selected"), std::string::npos) << e.what();
    }
  }
  // Only a vertex that no face uses selected: it traced nothing and wrote
  // zeros with success (an outside audit); refused as well.
  FilterInput in;
  in.scene = sf.scene;
  in.scene.positions.push_back(sf.scene.positions[0] + glm::vec3(0.01f));
  in.attrs = sf.attrs;
  in.attrs.vertexSelected.assign(nv + 1, 0);
  in.attrs.vertexSelected[nv] = 1;
  in.layers.push_back({"mesh", 0, sf.scene.faceCount()});
  in.values = defaultValues(filterSpecs(FilterKind::PathTracedReference), analyzeScene(in.scene).diagonal);
  in.values.set("emitter_source", int(kEmitterSources.index(EmitterSource::QualityAbove)));
  in.values.set("traced_selected", true);
  try {
    runFilter(FilterKind::PathTracedReference, in);
    ADD_FAILURE() << "a selection of an isolated vertex was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no selected vertex lies on a diffuse face"), std::string::npos) << e.what();
  }
}

// The PLY reader takes the selection from the vertex flags (bit 0x20, as
// MeshLab writes them), whatever the other bits.
TEST(ReferenceSubset, PlyVertexFlagsGiveTheSelection) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "property int flags\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0 0\n1 0 0 32\n1 1 0 3\n0 1 0 -2147483616\n3 0 1 2\n3 0 2 3\n";
  const io::LoadedMesh m = io::parseMesh(ply, "ply", "flags.ply");
  EXPECT_EQ(m.attrs.vertexSelected, (std::vector<uint8_t>{0, 1, 0, 1}));
  const io::LoadedMesh plain = io::parseMesh(
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
      "ply", "plain.ply");
  EXPECT_TRUE(plain.attrs.vertexSelected.empty());
}
