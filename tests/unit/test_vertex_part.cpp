// Splitting one mesh's vertices over parts (the ranks of an MPI run): every
// vertex in exactly one part, and the parts' values put together are the
// same bits as one run of the whole mesh, for every filter that can be
// split (per-vertex random numbers are keyed by the vertex, not by who
// computes it). The parts run in threads here, with an in-process stand-in
// for MPI_Allreduce, so that the test needs no MPI.
#include <gtest/gtest.h>

#include <condition_variable>
#include <cstring>
#include <mutex>
#include <thread>

#include "gi/filter_run.h"
#include "gi/scan.h"
#include "gi/vertex_order.h"
#include "gi/vertex_part.h"
#include "mesh_io.h"

using namespace gi;

namespace {

TEST(VertexPart, EveryVertexInExactlyOnePart) {
  for (size_t n : {0, 1, 5, 1023, 1024, 1025, 10000})
    for (uint32_t parts : {1u, 2u, 3u, 7u, 64u})
      for (uint32_t chunk : {1u, 7u, 1024u})
        for (bool interleaved : {true, false}) {
          std::vector<int> owner(n, 0);
          size_t total = 0;
          for (uint32_t p = 0; p < parts; ++p) {
            const VertexPart part{p, parts, chunk, interleaved, nullptr};
            const std::vector<uint32_t> v = part.vertices(n);
            ASSERT_EQ(v.size(), part.count(n));
            total += v.size();
            for (size_t k = 0; k < v.size(); ++k) {
              ASSERT_TRUE(part.contains(v[k], n));
              if (k) {
                ASSERT_LT(v[k - 1], v[k]);
              }
              if (k && !interleaved) {  // contiguous: one run of indices per part
                ASSERT_EQ(v[k - 1] + 1, v[k]);
              }
              ++owner[v[k]];
            }
          }
          ASSERT_EQ(total, n);
          for (size_t i = 0; i < n; ++i) ASSERT_EQ(owner[i], 1) << "vertex " << i << " of " << n;
        }
}

TEST(VertexPart, ContiguousPartsAreEvenToAChunk) {
  const size_t n = 100000;
  for (uint32_t parts : {2u, 3u, 16u}) {
    size_t lo = n, hi = 0;
    for (uint32_t p = 0; p < parts; ++p) {
      const size_t c = VertexPart{p, parts, 1000, false, nullptr}.count(n);
      lo = std::min(lo, c), hi = std::max(hi, c);
    }
    EXPECT_LE(hi - lo, 1000u) << parts << " parts";
  }
}

TEST(VertexPart, StatisticsOfThePartsAddUp) {
  RunStats a, b;
  a.add("vertices", 10), b.add("vertices", 10);
  a.add("rays", 100), b.add("rays", 50);
  a.add("seconds", 2), b.add("seconds", 3);
  a.add("rays_per_second", 50), b.add("rays_per_second", 25);
  a.add("mean", 0.5), b.add("mean", 0.25);
  a.warn("w"), b.warn("w");
  a.note("only a");
  const RunStats m = mergePartStats({a, b});
  EXPECT_EQ(m.get("vertices"), 10);
  EXPECT_EQ(m.get("rays"), 150);
  EXPECT_EQ(m.get("seconds"), 3);
  EXPECT_EQ(m.get("rays_per_second"), 75);
  EXPECT_EQ(m.get("mean", -1), -1);  // not combinable exactly: left out, and named in a note
  ASSERT_EQ(m.warnings.size(), 1u);
  EXPECT_EQ(m.warnings[0], "w");
  ASSERT_EQ(m.notes.size(), 2u);
  EXPECT_EQ(m.notes[0], "part 0 of 2: only a");
  EXPECT_NE(m.notes[1].find("mean"), std::string::npos);
}

// Element-wise sums among `parts` threads, each contributing once per round.
class SharedSum {
 public:
  explicit SharedSum(size_t parts) : parts_(parts) {}
  void operator()(std::vector<double>& v) {
    std::unique_lock<std::mutex> lock(m_);
    const size_t round = round_;
    if (arrived_ == 0) acc_.assign(v.size(), 0.0);
    for (size_t i = 0; i < v.size(); ++i) acc_[i] += v[i];
    if (++arrived_ == parts_) {
      sum_ = acc_;
      arrived_ = 0;
      ++round_;
      cv_.notify_all();
    } else {
      cv_.wait(lock, [&] { return round_ != round; });
    }
    v = sum_;
  }

 private:
  std::mutex m_;
  std::condition_variable cv_;
  size_t parts_, arrived_ = 0, round_ = 0;
  std::vector<double> acc_, sum_;
};

// Each triangle with its own three corners: neighbours in one plane become
// duplicate vertices (same position and normal), which ambient occlusion
// computes once, so a part must also compute the representatives its
// duplicates copy from other parts.
io::LoadedMesh unwelded(const io::LoadedMesh& m) {
  io::LoadedMesh u = m;
  u.scene.positions.clear();
  u.scene.vertexNormals.clear();
  u.attrs.vertexColor.clear();
  for (glm::uvec3& t : u.scene.triangles)
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = t[k];
      t[k] = uint32_t(u.scene.positions.size());
      u.scene.positions.push_back(m.scene.positions[v]);
      if (!m.attrs.vertexColor.empty()) u.attrs.vertexColor.push_back(m.attrs.vertexColor[v]);
    }
  return u;
}

FilterInput inputOf(const io::LoadedMesh& m, FilterKind kind, const std::map<std::string, std::string>& params) {
  FilterInput in;
  in.scene = m.scene;
  in.attrs = m.attrs;
  in.layers.push_back({"mesh", 0, m.scene.faceCount()});
  const auto specs = filterSpecs(kind);
  const double diag = analyzeScene(in.scene).diagonal;
  in.values = defaultValues(specs, diag);
  for (const auto& [k, v] : params) in.values.set(k, parseValue(*findSpec(specs, k), v, diag));
  return in;
}

template <class T>
bool sameBits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// Computes the filter whole and in `parts` parts (in threads), puts the
// parts' values together as a split run does, and compares every array.
void expectSplitEqualsWhole(const io::LoadedMesh& mesh, FilterKind kind, const std::map<std::string, std::string>& params,
                            uint32_t parts, uint32_t chunk, bool interleaved) {
  SCOPED_TRACE(filterDesc(kind).cliName + ", " + std::to_string(parts) + " parts of chunks of " + std::to_string(chunk) +
               (interleaved ? ", interleaved" : ", contiguous"));
  FilterInput wholeIn = inputOf(mesh, kind, params);
  const FilterResult whole = runFilter(kind, wholeIn);

  std::vector<FilterInput> ins;
  std::vector<FilterResult> rs;
  SharedSum shared(parts);
  for (uint32_t p = 0; p < parts; ++p) {
    ins.push_back(inputOf(mesh, kind, params));
    rs.push_back(prepareFilter(kind, ins.back()));
    ins.back().vertices = VertexPart{p, parts, chunk, interleaved, [&shared](std::vector<double>& v) { shared(v); }};
  }
  std::vector<std::thread> threads;
  for (uint32_t p = 0; p < parts; ++p)
    threads.emplace_back([&, p] { estimateFilter(kind, ins[p], rs[p]); });
  for (auto& t : threads) t.join();

  FilterResult merged = rs[0];
  const size_t n = merged.refined ? merged.refined->scene.vertexCount() : ins[0].scene.vertexCount();
  for (const FilterResult& r : rs) {  // every part on the same (refined) mesh
    ASSERT_EQ(r.refined.has_value(), merged.refined.has_value());
    if (r.refined) {
      ASSERT_TRUE(sameBits(r.refined->scene.positions, merged.refined->scene.positions));
    }
  }
  for (uint32_t p = 1; p < parts; ++p)
    for (uint32_t v : ins[p].vertices.vertices(n)) {
      if (!merged.vertexQuality.empty()) merged.vertexQuality[v] = rs[p].vertexQuality[v];
      if (!merged.vertexNormal.empty()) merged.vertexNormal[v] = rs[p].vertexNormal[v];
      for (size_t a = 0; a < merged.attributes.size(); ++a) {
        const int c = merged.attributes[a].components;
        for (int k = 0; k < c; ++k) merged.attributes[a].values[v * c + k] = rs[p].attributes[a].values[v * c + k];
      }
    }
  std::vector<RunStats> stats;
  for (const FilterResult& r : rs) stats.push_back(r.stats);
  merged.stats = mergePartStats(stats);
  outputFilter(kind, ins[0], merged);

  EXPECT_TRUE(sameBits(merged.vertexQuality, whole.vertexQuality));
  ASSERT_EQ(merged.vertexColor.size(), whole.vertexColor.size());
  for (size_t i = 0; i < whole.vertexColor.size(); ++i)
    ASSERT_TRUE(merged.vertexColor[i].r == whole.vertexColor[i].r && merged.vertexColor[i].g == whole.vertexColor[i].g &&
                merged.vertexColor[i].b == whole.vertexColor[i].b)
        << "colour of vertex " << i;
  EXPECT_TRUE(sameBits(merged.vertexNormal, whole.vertexNormal));
  EXPECT_TRUE(sameBits(merged.faceQuality, whole.faceQuality));
  ASSERT_EQ(merged.attributes.size(), whole.attributes.size());
  for (size_t a = 0; a < whole.attributes.size(); ++a) {
    EXPECT_EQ(merged.attributes[a].name, whole.attributes[a].name);
    EXPECT_TRUE(sameBits(merged.attributes[a].values, whole.attributes[a].values)) << whole.attributes[a].name;
  }
  EXPECT_EQ(merged.stats.get("vertices"), whole.stats.get("vertices"));
}

io::LoadedMesh cornell() { return io::loadMesh(std::string(GI_TEST_MESHES) + "/cornell_box.ply"); }

TEST(SplitRun, AmbientOcclusionWithDuplicatesOpenVerticesAndBentNormals) {
  const io::LoadedMesh m = unwelded(cornell());
  // max_distance lets provably open vertices skip their rays; bent normals replace the normals.
  const std::map<std::string, std::string> p = {{"rays_per_vertex", "32"},
                                                {"max_distance", "20%"},
                                                {"bent_normals_to_vertex_normals", "true"}};
  for (uint32_t parts : {2u, 3u}) expectSplitEqualsWhole(m, FilterKind::AmbientOcclusion, p, parts, 7, true);
  expectSplitEqualsWhole(m, FilterKind::AmbientOcclusion, p, 4, 50, false);
  expectSplitEqualsWhole(m, FilterKind::AmbientOcclusion, {{"target_error", "0.05"}, {"max_rays", "256"}}, 3, 16, true);
}

// Adaptive strata: each vertex's rays keyed by its index in the mesh, so a
// split run gives the whole run's bits, with duplicates, open vertices and
// bent normals.
TEST(SplitRun, AmbientOcclusionByAdaptiveStrata) {
  const io::LoadedMesh m = unwelded(cornell());
  const std::map<std::string, std::string> p = {{"estimator", "2"}, {"rays_per_vertex", "32"}, {"max_distance", "20%"},
                                                {"bent_normals_to_vertex_normals", "true"}};
  expectSplitEqualsWhole(m, FilterKind::AmbientOcclusion, p, 3, 7, true);
  expectSplitEqualsWhole(cornell(), FilterKind::AmbientOcclusion, {{"estimator", "2"}, {"rays_per_vertex", "128"}}, 2,
                         50, false);
  // to a target: rounds per vertex, keyed by the mesh's index as the fixed grid
  expectSplitEqualsWhole(cornell(), FilterKind::AmbientOcclusion,
                         {{"estimator", "2"}, {"target_error", "0.01"}, {"min_rays", "8"}, {"max_rays", "1024"}}, 3, 11,
                         true);
}

// The shared estimator pools neighbours' rays across the parts' borders:
// each round the parts exchange their vertices' rays (sumOverParts), so the
// pools, the adaptive rounds and every value are the whole run's. Welded
// (pools span many vertices) and unwelded (duplicates, computed once by
// their representative's part); fixed and adaptive; with open vertices.
TEST(SplitRun, SharedAmbientOcclusion) {
  const io::LoadedMesh welded = cornell();
  const std::map<std::string, std::string> fixed = {{"estimator", "1"}, {"rays_per_vertex", "16"}, {"max_distance", "20%"},
                                                    {"bent_normals_to_vertex_normals", "true"}};
  const std::map<std::string, std::string> adaptive = {{"estimator", "1"}, {"target_error", "0.03"}, {"min_rays", "8"},
                                                       {"max_rays", "512"}};
  expectSplitEqualsWhole(welded, FilterKind::AmbientOcclusion, fixed, 3, 7, true);
  expectSplitEqualsWhole(welded, FilterKind::AmbientOcclusion, adaptive, 4, 50, false);
  expectSplitEqualsWhole(welded, FilterKind::AmbientObscurance, {{"estimator", "1"}, {"rays_per_vertex", "16"}}, 2, 13, true);
  expectSplitEqualsWhole(unwelded(welded), FilterKind::AmbientOcclusion, adaptive, 3, 16, true);
}

// A mesh large enough to be computed in its spatial order (gi/vertex_order.h):
// each part still computes the chunks of the mesh's indices it was given, and
// the shared estimator's exchanges between parts (in the reordered copy's
// places, the same in every part) give the whole run's pools.
TEST(SplitRun, AmbientOcclusionOfAReorderedMesh) {
  io::LoadedMesh m;
  scenes::ScanOptions o;
  o.levels = 3;
  m.scene = scenes::displacedScan(io::loadMesh(std::string(GI_TEST_MESHES) + "/bunny.ply").scene, o);  // 118k vertices
  ASSERT_GE(m.scene.vertexCount(), kSpatialOrderFrom);
  expectSplitEqualsWhole(m, FilterKind::AmbientOcclusion, {{"rays_per_vertex", "4"}}, 2, 1024, true);
  expectSplitEqualsWhole(m, FilterKind::AmbientOcclusion,
                         {{"estimator", "1"}, {"target_error", "0.05"}, {"min_rays", "4"}, {"max_rays", "32"}}, 3, 4096,
                         false);
}

// Without the parts' sum a split shared run cannot see its neighbours' rays: refused.
TEST(SplitRun, PoolingNeedsThePartsSum) {
  FilterInput in = inputOf(cornell(), FilterKind::AmbientOcclusion, {{"estimator", "1"}, {"rays_per_vertex", "8"}});
  FilterResult r = prepareFilter(FilterKind::AmbientOcclusion, in);
  in.vertices = VertexPart{0, 2, 64, true, nullptr};
  EXPECT_THROW(estimateFilter(FilterKind::AmbientOcclusion, in, r), std::logic_error);
  // So is a split radiosity run that pools its gather.
  FilterInput rin = inputOf(cornell(), FilterKind::Radiosity,
                            {{"emitter_source", "1"}, {"gather_rays", "8"}, {"gather_share_rings", "1"}});
  FilterResult rr = prepareFilter(FilterKind::Radiosity, rin);
  rin.vertices = VertexPart{0, 2, 64, true, nullptr};
  EXPECT_THROW(estimateFilter(FilterKind::Radiosity, rin, rr), std::logic_error);
}

TEST(SplitRun, ObscuranceAndSky) {
  const io::LoadedMesh m = cornell();
  expectSplitEqualsWhole(m, FilterKind::AmbientObscurance, {{"rays_per_vertex", "32"}}, 3, 5, true);
  expectSplitEqualsWhole(m, FilterKind::SkyLighting, {{"rays_per_vertex", "32"}, {"sun_rays", "8"}}, 4, 9, false);
}

TEST(SplitRun, ReferenceFixedAndAdaptive) {
  const io::LoadedMesh m = cornell();
  expectSplitEqualsWhole(m, FilterKind::PathTracedReference, {{"emitter_source", "1"}, {"samples_per_vertex", "8"}}, 3, 11,
                         true);
  // Adaptive: every part needs the pilot's mean B over all vertices (summed across the parts).
  expectSplitEqualsWhole(m, FilterKind::PathTracedReference,
                         {{"emitter_source", "1"}, {"target_relative_error", "0.3"}, {"min_samples", "4"}, {"max_samples", "64"}},
                         3, 13, true);
}

TEST(SplitRun, RadiosityFinalGatherAndFaces) {
  const io::LoadedMesh m = cornell();
  const std::map<std::string, std::string> p = {{"emitter_source", "1"}, {"rays_per_patch", "64"}, {"light_samples", "16"},
                                                {"gather_rays", "16"}, {"face_output", "true"}};
  expectSplitEqualsWhole(m, FilterKind::Radiosity, p, 3, 17, true);
  expectSplitEqualsWhole(m, FilterKind::Radiosity, p, 2, 64, false);
  // Pooling the gather across the parts' borders: the parts exchange their rays' sums.
  std::map<std::string, std::string> shared = p;
  shared["gather_share_rings"] = "2";
  expectSplitEqualsWhole(m, FilterKind::Radiosity, shared, 3, 17, true);
  // Refinement decides from every vertex's value at the coarser levels: each part refines alike.
  std::map<std::string, std::string> refine = p;
  refine["refine"] = "true", refine["refine_max_depth"] = "1";
  expectSplitEqualsWhole(m, FilterKind::Radiosity, refine, 3, 29, true);
  refine["vertex_output"] = "Interpolated indirect";
  expectSplitEqualsWhole(m, FilterKind::Radiosity, refine, 2, 31, false);
}

TEST(SplitRun, AFilterOfAllVerticesTogetherIsNotSplit) {
  FilterInput in = inputOf(cornell(), FilterKind::PhotonMapping, {{"emitter_source", "1"}});
  FilterResult r = prepareFilter(FilterKind::PhotonMapping, in);
  in.vertices = VertexPart{1, 2, 64, true, nullptr};
  EXPECT_THROW(estimateFilter(FilterKind::PhotonMapping, in, r), std::invalid_argument);
  in.vertices = VertexPart{2, 2, 64, true, nullptr};  // no part 2 of 2
  EXPECT_THROW(estimateFilter(FilterKind::AmbientOcclusion, in, r), std::invalid_argument);
}

}  // namespace
