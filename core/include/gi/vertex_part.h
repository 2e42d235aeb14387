// A part of a mesh's vertices, for splitting one per-vertex computation over
// several processes (MPI ranks, docs/design.md "Split runs"). The vertices
// are cut into chunks of `chunk` consecutive indices, K = ceil(n / chunk)
// chunks in all; part p of P takes chunk k when
//   interleaved:  k mod P == p             (round robin: costly regions are shared out)
//   contiguous:   floor(k P / K) == p      (one run of chunks per part)
// Each vertex's random numbers are keyed by its index and the seed, never by
// who computes it, so the union of the parts' values is bit-identical to
// computing all vertices in one process. A subset (randomVertexSubset: the
// path-traced reference on a sample of a large mesh's vertices) narrows any
// part further to the vertices it marks.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "gi/run.h"

namespace gi {

struct VertexPart {
  uint32_t part = 0, parts = 1;
  uint32_t chunk = 1024;
  bool interleaved = true;
  // Sums `values` element by element over all parts, where each part has
  // filled its own entries and left the others 0 (MPI_Allreduce in a split
  // run), so that a quantity coupling all vertices (the adaptive reference's
  // mean B) is the same in every part. Unset: one part, nothing to do.
  std::function<void(std::vector<double>&)> sumOverParts;
  // Unset: every vertex of the part; else only those marked 1 (the same
  // subset in every part).
  std::shared_ptr<const std::vector<uint8_t>> subset;
  // Set when the computation runs on a copy of the mesh with its vertices
  // reordered (gi/vertex_order.h): the mesh's index of each vertex of the
  // copy. Chunks, parts and the subset stay those of the mesh's indices, so a
  // part computes the same vertices in either order. Null: the indices are
  // the mesh's.
  std::shared_ptr<const std::vector<uint32_t>> ids;

  bool all() const { return parts <= 1; }  // one part (a subset may still narrow it)
  // The mesh's index of vertex v.
  size_t meshIndex(size_t v) const { return ids ? (*ids)[v] : v; }
  // Whether vertex v is in the subset (true without one), whichever part holds it.
  bool inSubset(size_t v) const {
    const size_t m = meshIndex(v);
    return !subset || (m < subset->size() && (*subset)[m]);
  }
  // Whether vertex v of n belongs to this part.
  bool contains(size_t v, size_t n) const;
  // This part's vertices of n, ascending.
  std::vector<uint32_t> vertices(size_t n) const;
  size_t count(size_t n) const;
  // The same split for another part.
  VertexPart other(uint32_t p) const;
  // Throws std::invalid_argument with a sentence if the split is unusable.
  void check() const;
};

// The statistics of a split run from its parts' statistics: a number every
// part reports alike (the scene, a replicated patch solution) is kept; a
// count of work done (rays, paths, skipped vertices) is summed; a time is
// the slowest part's; a rate is summed (the parts ran at once). Other
// numbers that differ between parts (means and error estimates over a part's
// vertices) cannot be combined exactly from the parts: they are left out and
// a note names them. Notes and warnings are kept once; those of only some
// parts say which part.
// `count` of the n vertices drawn without replacement, uniformly and
// deterministically from the seed (the smallest keys hash(v, seed)),
// independent of threads and parts; count >= n marks all.
std::shared_ptr<const std::vector<uint8_t>> randomVertexSubset(size_t n, size_t count, uint32_t seed);

RunStats mergePartStats(const std::vector<RunStats>& parts);

}  // namespace gi
