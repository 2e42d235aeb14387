#include "face_twins.h"

#include <algorithm>
#include <array>
#include <cstring>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

namespace gi {
namespace {

using Corner = std::array<float, 3>;

struct Key {
  uint64_t hash;
  uint32_t prim;
  bool operator<(const Key& o) const { return hash != o.hash ? hash < o.hash : prim < o.prim; }
};

// A face's corners in lexicographic order, and whether that order is a
// rotation of the face's own (its turn) or a reflection of it.
struct Sorted {
  Corner c[3];
  bool even;
};

Corner cornerOf(const float* xyz, uint32_t v) {
  Corner c;
  for (int a = 0; a < 3; ++a) c[a] = xyz[3 * size_t(v) + a] + 0.f;  // -0 and +0 as one
  return c;
}

Sorted sortedCorners(const float* xyz, const uint32_t* tri) {
  const Corner p[3] = {cornerOf(xyz, tri[0]), cornerOf(xyz, tri[1]), cornerOf(xyz, tri[2])};
  int o[3] = {0, 1, 2};
  std::sort(o, o + 3, [&](int a, int b) { return p[a] < p[b]; });
  Sorted s;
  for (int k = 0; k < 3; ++k) s.c[k] = p[o[k]];
  // (0 1 2), (1 2 0) and (2 0 1) keep the turn.
  s.even = (o[1] == (o[0] + 1) % 3);
  return s;
}

// A well-mixed 64-bit hash of a position (splitmix64's finaliser over its
// coordinates' bits); a face's key is the sum over its corners, the same in
// any order, so the corners need no sorting to be compared.
uint64_t mix(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}
uint64_t hashOf(const Corner& p) {
  uint64_t h = 0x9e3779b97f4a7c15ull;
  for (int a = 0; a < 3; ++a) {
    uint32_t b;
    std::memcpy(&b, &p[size_t(a)], sizeof b);
    h = mix(h + b);
  }
  return h;
}

}  // namespace

FaceTwins::FaceTwins(const float* xyz, const uint32_t* idx, size_t n) {
  uint32_t nv = 0;
  for (size_t k = 0; k < 3 * n; ++k) nv = std::max(nv, idx[k] + 1);
  std::vector<uint64_t> vh(nv);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v < r.end(); ++v) vh[v] = hashOf(cornerOf(xyz, uint32_t(v)));
  });
  std::vector<Key> keys(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t p = r.begin(); p < r.end(); ++p) {
      const uint32_t* t = idx + 3 * p;
      keys[p] = {vh[t[0]] + vh[t[1]] + vh[t[2]], uint32_t(p)};
    }
  });
  tbb::parallel_sort(keys.begin(), keys.end());
  auto corner = [&](uint32_t p, int k) { return cornerOf(xyz, idx[3 * size_t(p) + size_t(k)]); };
  auto link = [&](uint32_t p, uint32_t q) {  // q is p's reversed copy
    if (!any_) {
      twin_.assign(n, kNoHit);
      corner_.assign(n, 0);
      any_ = true;
    }
    twin_[p] = q;
    const Corner pc[3] = {corner(p, 0), corner(p, 1), corner(p, 2)};
    uint8_t m = 0;
    for (int k = 1; k <= 2; ++k) {
      const Corner qc = corner(q, k);
      const int c = qc == pc[0] ? 0 : qc == pc[1] ? 1 : 2;
      m |= uint8_t(c << (2 * (k - 1)));
    }
    corner_[p] = m;
  };
  struct Entry {
    Sorted s;
    uint32_t prim;
  };
  std::vector<Entry> run;
  for (size_t b = 0; b < n;) {
    size_t e = b + 1;
    while (e < n && keys[e].hash == keys[b].hash) ++e;
    if (e - b > 1) {
      // A run of faces on the same corners (or a hash collision), sorted by
      // their exact corners and turn (n log n however many copies a hostile
      // mesh stacks on one triangle): each takes the first face of the
      // opposite turn on exactly the same corners.
      run.clear();
      for (size_t i = b; i < e; ++i) run.push_back({sortedCorners(xyz, idx + 3 * size_t(keys[i].prim)), keys[i].prim});
      std::sort(run.begin(), run.end(), [](const Entry& x, const Entry& y) {
        if (!std::equal(x.s.c, x.s.c + 3, y.s.c)) return std::lexicographical_compare(x.s.c, x.s.c + 3, y.s.c, y.s.c + 3);
        return x.s.even != y.s.even ? x.s.even : x.prim < y.prim;
      });
      for (size_t g = 0; g < run.size();) {
        size_t h = g + 1;
        while (h < run.size() && std::equal(run[g].s.c, run[g].s.c + 3, run[h].s.c)) ++h;
        // [g, h): one set of corners, the even turn first.
        size_t odd = g;
        while (odd < h && run[odd].s.even) ++odd;
        if (odd > g && odd < h)
          for (size_t i = g; i < h; ++i) link(run[i].prim, run[i < odd ? odd : g].prim);
        g = h;
      }
    }
    b = e;
  }
}

SceneFaceTwins sceneFaceTwins(const Scene& s) {
  SceneFaceTwins out;
  const std::vector<uint8_t> ok = usableFaceMask(s);
  std::vector<float> xyz;
  xyz.reserve(3 * s.positions.size());
  for (const glm::vec3& p : s.positions) xyz.insert(xyz.end(), {p.x, p.y, p.z});
  std::vector<uint32_t> idx;
  out.primOf.assign(ok.size(), kNoHit);
  for (size_t f = 0; f < ok.size(); ++f)
    if (ok[f]) {
      idx.insert(idx.end(), {s.triangles[f].x, s.triangles[f].y, s.triangles[f].z});
      out.primOf[f] = uint32_t(out.faceOf.size());
      out.faceOf.push_back(uint32_t(f));
    }
  out.twins = std::make_unique<FaceTwins>(xyz.data(), idx.data(), out.faceOf.size());
  return out;
}

}  // namespace gi
