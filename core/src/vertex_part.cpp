#include "gi/vertex_part.h"

#include <algorithm>
#include <map>
#include <stdexcept>
#include <string>

#include "gi/sampling.h"

namespace gi {

namespace {

// Counts of work a part did: the whole run did their sum.
bool isTotal(const std::string& key) {
  static const char* const totals[] = {"rays", "paths", "traced_vertices", "gather_rays", "gather_near_hits_relit", "paths_cut_at_max_depth",
                                       "shadow_rays", "skipped_open", "skipped_duplicates", "skipped_invalid"};
  for (const char* t : totals)
    if (key == t) return true;
  return false;
}

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// Texts (notes or warnings) of all parts: once if every part has it, else
// prefixed with the parts that have it.
std::vector<std::string> mergeTexts(const std::vector<RunStats>& parts, std::vector<std::string> RunStats::*field) {
  std::vector<std::string> order;
  std::map<std::string, std::vector<size_t>> who;
  for (size_t p = 0; p < parts.size(); ++p)
    for (const std::string& t : parts[p].*field) {
      auto& w = who[t];
      if (w.empty()) order.push_back(t);
      if (w.empty() || w.back() != p) w.push_back(p);
    }
  std::vector<std::string> out;
  for (const std::string& t : order) {
    const auto& w = who[t];
    if (w.size() == parts.size()) {
      out.push_back(t);
      continue;
    }
    std::string s = w.size() == 1 ? "part " : "parts ";
    for (size_t i = 0; i < w.size(); ++i) s += (i ? "," : "") + std::to_string(w[i]);
    out.push_back(s + " of " + std::to_string(parts.size()) + ": " + t);
  }
  return out;
}

}  // namespace

bool VertexPart::contains(size_t v, size_t n) const {
  if (!inSubset(v)) return false;
  if (parts <= 1) return true;
  const uint64_t k = meshIndex(v) / chunk;
  if (interleaved) return k % parts == part;
  const uint64_t K = (uint64_t(n) + chunk - 1) / chunk;
  return k * parts / K == part;
}

std::vector<uint32_t> VertexPart::vertices(size_t n) const {
  std::vector<uint32_t> v;
  v.reserve(parts ? n / parts + chunk : n);
  if (subset || ids) {
    for (size_t i = 0; i < n; ++i)
      if (contains(i, n)) v.push_back(uint32_t(i));
    return v;
  }
  for (size_t i = 0; i < n; i += chunk)
    if (contains(i, n))
      for (size_t j = i; j < std::min(n, i + chunk); ++j) v.push_back(uint32_t(j));
  return v;
}

size_t VertexPart::count(size_t n) const {
  size_t c = 0;
  if (subset || ids) {
    for (size_t i = 0; i < n; ++i) c += contains(i, n) ? 1 : 0;
    return c;
  }
  for (size_t i = 0; i < n; i += chunk)
    if (contains(i, n)) c += std::min(n, i + chunk) - i;
  return c;
}

VertexPart VertexPart::other(uint32_t p) const {
  VertexPart o = *this;
  o.part = p;
  return o;
}

void VertexPart::check() const {
  if (parts < 1) throw std::invalid_argument("a vertex split needs at least one part");
  if (part >= parts)
    throw std::invalid_argument("vertex part " + std::to_string(part) + " does not exist (parts 0 to " +
                                std::to_string(parts - 1) + ")");
  if (chunk < 1) throw std::invalid_argument("the vertex chunk must hold at least one vertex");
}

std::shared_ptr<const std::vector<uint8_t>> randomVertexSubset(size_t n, size_t count, uint32_t seed) {
  auto mask = std::make_shared<std::vector<uint8_t>>(n, uint8_t(count >= n ? 1 : 0));
  if (count >= n) return mask;
  // Keys (hash, index): distinct, so the chosen set is unique for any sort.
  std::vector<std::pair<uint32_t, uint32_t>> key(n);
  for (size_t v = 0; v < n; ++v) key[v] = {hash3(uint32_t(v), seed, 0x5e1ecu), uint32_t(v)};
  std::nth_element(key.begin(), key.begin() + std::ptrdiff_t(count), key.end());
  for (size_t k = 0; k < count; ++k) (*mask)[key[k].second] = 1;
  return mask;
}

RunStats mergePartStats(const std::vector<RunStats>& parts) {
  if (parts.empty()) return {};
  if (parts.size() == 1) return parts[0];
  RunStats out;
  std::vector<std::string> dropped;
  for (const auto& [key, v0] : parts[0].numbers) {
    bool same = true, everywhere = true;
    double sum = 0.0, mx = v0;
    for (const RunStats& p : parts) {
      bool found = false;
      for (const auto& [k, v] : p.numbers)
        if (k == key) {
          found = true;
          same = same && v == v0;
          sum += v;
          mx = std::max(mx, v);
          break;
        }
      everywhere = everywhere && found;
    }
    if (everywhere && isTotal(key)) out.add(key, sum);
    else if (everywhere && endsWith(key, "per_second")) out.add(key, sum);
    else if (everywhere && endsWith(key, "seconds")) out.add(key, mx);
    else if (everywhere && same) out.add(key, v0);
    else dropped.push_back(key);
  }
  out.warnings = mergeTexts(parts, &RunStats::warnings);
  out.notes = mergeTexts(parts, &RunStats::notes);
  if (!dropped.empty()) {
    std::string s = "over the parts' vertices only, not combined:";
    for (size_t i = 0; i < dropped.size(); ++i) s += (i ? ", " : " ") + dropped[i];
    out.note(s);
  }
  return out;
}

}  // namespace gi
