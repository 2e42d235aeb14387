// gi_cluster.h with MPI (the GI_MPI build option): one mesh split over the
// ranks of MPI_COMM_WORLD. Every rank holds the whole scene; rank r computes
// gi::VertexPart {r, N, chunk} of the vertices; rank 0 gathers each
// per-vertex array with MPI_Gatherv, merges the statistics and finishes.
#include <mpi.h>
#include <sys/resource.h>

#include <algorithm>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <string>
#include <vector>

#include "gi/memory_limit.h"
#include "gi/params.h"
#include "gi_cluster.h"
#include "gi_output.h"

namespace gi::cluster {

namespace {

bool g_started = false, g_checked = false;
int g_rank = 0, g_size = 1;
nlohmann::json g_report = nullptr;

// Launchers that start ranks: Open MPI's mpirun, PMIx (srun --mpi=pmix), Hydra.
bool launchedByMpi() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(v)) return true;
  return false;
}

// The first collective of a run: the lowest rank that failed before it, or INT_MAX.
int firstFailure(bool ok) {
  g_checked = true;
  int mine = ok ? INT_MAX : g_rank, lowest = INT_MAX;
  MPI_Allreduce(&mine, &lowest, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  return lowest;
}

[[noreturn]] void abortRun(const std::string& what) {
  std::fprintf(stderr, "gi: error: rank %d of %d: %s\n", g_rank, g_size, what.c_str());
  std::fflush(stderr);
  MPI_Abort(MPI_COMM_WORLD, 1);
  std::abort();
}

double peakMB() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;  // kilobytes on Linux
}

// CPU seconds of this process, all threads: a rank's work even where ranks share cores.
double cpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// Element-wise sum over the ranks, in blocks that fit MPI's int counts.
void sumOverRanks(std::vector<double>& v) {
  const size_t block = size_t(1) << 28;
  for (size_t b = 0; b < v.size(); b += block)
    MPI_Allreduce(MPI_IN_PLACE, v.data() + b, int(std::min(block, v.size() - b)), MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
}

// Strings of every rank on rank 0 (empty elsewhere).
std::vector<std::string> gatherText(const std::string& mine) {
  int n = int(mine.size());
  const size_t ranks = static_cast<size_t>(g_size);
  std::vector<int> counts(ranks), displs(ranks);
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  std::vector<char> all;
  if (g_rank == 0) {
    for (int r = 1; r < g_size; ++r) displs[size_t(r)] = displs[size_t(r) - 1] + counts[size_t(r) - 1];
    all.resize(size_t(displs.back() + counts.back()));
  }
  MPI_Gatherv(mine.data(), n, MPI_CHAR, all.data(), counts.data(), displs.data(), MPI_CHAR, 0, MPI_COMM_WORLD);
  std::vector<std::string> out;
  if (g_rank == 0)
    for (int r = 0; r < g_size; ++r) out.emplace_back(all.data() + displs[size_t(r)], size_t(counts[size_t(r)]));
  return out;
}

nlohmann::json statsJson(const RunStats& s) {
  return {{"numbers", s.numbers}, {"notes", s.notes}, {"warnings", s.warnings}};
}

RunStats statsFrom(const nlohmann::json& j) {
  RunStats s;
  s.numbers = j.at("numbers").get<std::vector<std::pair<std::string, double>>>();
  s.notes = j.at("notes").get<std::vector<std::string>>();
  s.warnings = j.at("warnings").get<std::vector<std::string>>();
  return s;
}

// Rank 0 receives every rank's values of array `a` (components floats per
// vertex, the rank's vertices in order) and puts them in place. Returns the
// bytes received.
double gatherArray(float* a, size_t n, int components, const VertexPart& part) {
  const size_t ranks = static_cast<size_t>(g_size);
  std::vector<int> counts(ranks), displs(ranks);
  for (int r = 0; r < g_size; ++r) {
    const size_t c = part.other(uint32_t(r)).count(n) * size_t(components);
    if (c > size_t(INT_MAX)) throw std::length_error("a rank's part exceeds 2^31 values: use more ranks");
    counts[size_t(r)] = int(c);
    if (r) displs[size_t(r)] = displs[size_t(r) - 1] + counts[size_t(r) - 1];
  }
  std::vector<float> mine;
  mine.reserve(size_t(counts[size_t(g_rank)]));
  for (size_t i = 0; i < n; i += part.chunk)
    if (part.contains(i, n)) mine.insert(mine.end(), a + i * components, a + std::min(n, i + part.chunk) * components);
  std::vector<float> all(g_rank == 0 ? n * size_t(components) : 0);
  MPI_Gatherv(mine.data(), int(mine.size()), MPI_FLOAT, all.data(), counts.data(), displs.data(), MPI_FLOAT, 0,
              MPI_COMM_WORLD);
  if (g_rank != 0) return 0.0;
  for (int r = 0; r < g_size; ++r) {
    const VertexPart p = part.other(uint32_t(r));
    const float* src = all.data() + displs[size_t(r)];
    for (size_t i = 0; i < n; i += p.chunk)
      if (p.contains(i, n)) {
        const size_t m = (std::min(n, i + p.chunk) - i) * size_t(components);
        std::copy(src, src + m, a + i * components);
        src += m;
      }
  }
  return double(all.size()) * sizeof(float);
}

}  // namespace

void start(int* argc, char*** argv) {
  if (!launchedByMpi()) return;
  MPI_Init(argc, argv);
  g_started = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_size);
  // The ranks on one machine start together and would each see all of its
  // memory: each takes its share (gi/memory_limit.h).
  MPI_Comm node;
  int local = 1;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, g_rank, MPI_INFO_NULL, &node);
  MPI_Comm_size(node, &local);
  MPI_Comm_free(&node);
  shareMemoryWith(local);
}

void stop() {
  if (g_started) MPI_Finalize();
  g_started = false;
}

int rank() { return g_rank; }
int size() { return g_size; }

bool abandon() {
  if (g_size == 1 || g_checked) return g_rank == 0 || g_checked;
  return firstFailure(false) == g_rank;
}

void compute(FilterKind kind, FilterInput& in, FilterResult& res, const Progress& progress, const SplitOptions& split) {
  // One rank runs the split path too (its gather and report), except for a filter that cannot be split.
  if (!g_started || (g_size == 1 && !splitsVertices(kind))) return computeFilter(kind, in, res, progress);
  if (!splitsVertices(kind))
    throw std::invalid_argument("'" + filterDesc(kind).cliName + "' computes all vertices together and cannot be "
                                "split over MPI ranks: run it without mpirun (ao, obscurance, sky, reference and "
                                "radiosity can be split)");
  if (split.chunk < 1) throw std::invalid_argument("--chunk must be at least 1");
  if (firstFailure(true) != INT_MAX) throw Quiet();
  // Every rank must compute the same job: the filter, its parameters, the
  // split and the scene (an outside audit: a rank given another --chunk,
  // --seed or a stale copy of the mesh of the same vertex count wrote wrong
  // values without a word; ranks running different filters overran rank 0's
  // gather buffer).
  {
    const std::string job = std::to_string(int(kind)) + "\n" + describe(filterSpecs(kind), in.values) + "\n" +
                            std::to_string(split.chunk) + (split.interleaved ? " interleaved\n" : " contiguous\n");
    const uint64_t scene = sceneHash(in.scene);
    unsigned long long h = fnv1a(fnv1a(kFnvOffset, job.data(), job.size()), &scene, sizeof scene);
    unsigned long long lo = 0, hi = 0;
    MPI_Allreduce(&h, &lo, 1, MPI_UNSIGNED_LONG_LONG, MPI_MIN, MPI_COMM_WORLD);
    MPI_Allreduce(&h, &hi, 1, MPI_UNSIGNED_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
    if (lo != hi) {
      if (g_rank == 0)
        throw std::invalid_argument("the ranks were given different jobs (another filter, parameter, --split or "
                                    "--chunk, or another mesh): every rank must run the same command on the same files");
      throw Quiet();
    }
  }

  VertexPart part;
  part.part = uint32_t(g_rank);
  part.parts = uint32_t(g_size);
  part.chunk = split.chunk;
  part.interleaved = split.interleaved;
  part.sumOverParts = sumOverRanks;
  in.vertices = part;
  // The estimate: a parameter error (std::invalid_argument) is found alike on
  // every rank before any collective, and reported once; any other failure
  // is this rank's own (memory, say) and may leave the others inside a
  // collective: it ends the whole run.
  Timer timer;
  const double cpu0 = cpuSeconds();
  std::string paramError;
  try {
    estimateFilter(kind, in, res, g_rank == 0 ? progress : Progress(nullptr));
  } catch (const std::invalid_argument& e) {
    paramError = e.what();
  } catch (const std::bad_alloc&) {
    abortRun("out of memory");
  } catch (const std::exception& e) {
    abortRun(e.what());
  }
  const double seconds = timer.seconds(), cpu = cpuSeconds() - cpu0;
  int mine = paramError.empty() ? INT_MAX : g_rank, lowest = INT_MAX;
  MPI_Allreduce(&mine, &lowest, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (lowest != INT_MAX) {
    if (lowest == g_rank) throw std::invalid_argument(paramError);
    throw Quiet();
  }

  // The gather: each per-vertex array in turn, every rank the same arrays.
  Timer gatherTimer;
  const size_t n = res.refined ? res.refined->scene.vertexCount() : in.scene.vertexCount();
  std::vector<std::pair<float*, int>> arrays;
  if (!res.vertexQuality.empty()) arrays.push_back({res.vertexQuality.data(), 1});
  if (!res.vertexNormal.empty()) arrays.push_back({&res.vertexNormal[0].x, 3});
  for (VertexAttribute& a : res.attributes)
    if (!a.values.empty()) arrays.push_back({a.values.data(), a.components});
  long long shape[2] = {(long long)arrays.size(), (long long)n}, lo[2], hi[2];
  MPI_Allreduce(shape, lo, 2, MPI_LONG_LONG, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(shape, hi, 2, MPI_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
  if (lo[0] != hi[0] || lo[1] != hi[1]) abortRun("the ranks computed different results (did they load the same files?)");
  double bytes = 0.0, buffer = 0.0;
  for (const auto& [a, c] : arrays) {
    bytes += gatherArray(a, n, c, part);
    buffer = std::max(buffer, g_rank == 0 ? double(n) * c * sizeof(float) : 0.0);
  }
  res.vertexColor.clear();

  // Statistics and measurements of every rank.
  nlohmann::json me = {{"rank", g_rank},
                       {"vertices", part.count(n)},
                       {"seconds", seconds},
                       {"cpu_seconds", cpu},
                       {"rays", res.stats.get("rays")},
                       {"peak_memory_MB", peakMB()},
                       {"stats", statsJson(res.stats)}};
  const std::vector<std::string> all = gatherText(me.dump());
  const double gatherSeconds = gatherTimer.seconds();
  if (g_rank != 0) return;
  std::vector<RunStats> stats;
  nlohmann::json ranks = nlohmann::json::array();
  double slowest = 0.0, mean = 0.0;
  for (const std::string& t : all) {
    nlohmann::json r = nlohmann::json::parse(t);
    stats.push_back(statsFrom(r["stats"]));
    r.erase("stats");
    slowest = std::max(slowest, r["seconds"].get<double>());
    mean += r["seconds"].get<double>() / g_size;
    ranks.push_back(r);
  }
  res.stats = mergePartStats(stats);
  res.stats.add("ranks", g_size);
  res.stats.add("slowest_rank_seconds", slowest);
  res.stats.add("gather_seconds", gatherSeconds);
  outputFilter(kind, in, res);
  g_report = {{"ranks", g_size},
              {"split", split.interleaved ? "interleaved" : "contiguous"},
              {"chunk", split.chunk},
              {"slowest_seconds", slowest},
              {"mean_seconds", mean},
              {"imbalance", mean > 0 ? slowest / mean : 1.0},
              {"gather_seconds", gatherSeconds},
              {"gather_MB", bytes / 1048576.0},
              {"gather_buffer_MB", buffer / 1048576.0},
              {"per_rank", ranks}};
}

nlohmann::json report() { return g_report; }

}  // namespace gi::cluster
