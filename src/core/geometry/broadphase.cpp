#include "geometry/broadphase.h"

#include <algorithm>
#include <cmath>

namespace collision_response::core {

std::uint64_t SpatialHash::key(std::int64_t x, std::int64_t y, std::int64_t z) {
  // 21 bits a coordinate: cells far apart may share a key (wrapping), which only adds candidate
  // pairs that the overlap test then removes.
  constexpr std::uint64_t kMask = (std::uint64_t{1} << 21) - 1;
  return (static_cast<std::uint64_t>(x) & kMask) | ((static_cast<std::uint64_t>(y) & kMask) << 21) |
         ((static_cast<std::uint64_t>(z) & kMask) << 42);
}

SpatialHash::Cell SpatialHash::cellOf(const Eigen::Vector3d& point) const {
  const auto index = [this](double value) {
    const double scaled = std::floor(value / cell_size_);
    // Clamp far outliers so the conversion is defined; they share edge cells, harmlessly.
    return static_cast<std::int64_t>(std::clamp(scaled, -1e15, 1e15));
  };
  return Cell{index(point.x()), index(point.y()), index(point.z())};
}

template <typename Visit>
bool SpatialHash::forEachCell(const Box& box, Visit visit) const {
  // A box with a non-finite corner covers no countable set of cells: it is kept aside.
  if (!box.low.allFinite() || !box.high.allFinite()) return false;
  const Cell low = cellOf(box.low), high = cellOf(box.high);
  // Counted axis by axis, each against the limit before they are multiplied: the product of
  // three spans of up to 2e15 cells overflows int64, and a wrapped count once passed the limit
  // (a far, fast body then had the grid walk and store cells until memory ran out).
  std::int64_t count = 1;
  for (const auto& [from, to] :
       {std::pair{low.x, high.x}, std::pair{low.y, high.y}, std::pair{low.z, high.z}}) {
    if (to < from || to - from >= static_cast<std::int64_t>(kMaxCells)) return false;
    count *= to - from + 1;  // at most kMaxCells^3: no overflow
  }
  if (count > static_cast<std::int64_t>(kMaxCells)) return false;
  for (std::int64_t x = low.x; x <= high.x; ++x) {
    for (std::int64_t y = low.y; y <= high.y; ++y) {
      for (std::int64_t z = low.z; z <= high.z; ++z) visit(key(x, y, z));
    }
  }
  return true;
}

void SpatialHash::build(const std::vector<Box>& boxes, const std::vector<char>& active) {
  boxes_ = &boxes;
  active_ = &active;
  keyed_.clear();
  entries_.clear();
  large_.clear();
  bucket_bits_ = 0;
  bucket_start_.assign(2, 0);
  std::vector<double> extents;
  extents.reserve(boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const double extent = (boxes[i].high - boxes[i].low).maxCoeff();
    if (active[i] && std::isfinite(extent)) extents.push_back(extent);
  }
  cell_size_ = 1.0;
  if (!extents.empty()) {
    std::nth_element(extents.begin(), extents.begin() + extents.size() / 2, extents.end());
    const double median = extents[extents.size() / 2];
    if (median > 0) cell_size_ = median;
  }
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    if (!active[i]) continue;
    const std::size_t before = keyed_.size();
    if (!forEachCell(boxes[i], [&](std::uint64_t k) { keyed_.emplace_back(k, i); })) {
      keyed_.resize(before);
      large_.push_back(i);
    }
  }
  // About two buckets an entry; a counting sort groups the entries by bucket.
  while ((std::size_t{1} << bucket_bits_) < 2 * keyed_.size() && bucket_bits_ < 40) ++bucket_bits_;
  const std::size_t buckets = std::size_t{1} << bucket_bits_;
  bucket_start_.assign(buckets + 1, 0);
  for (const auto& entry : keyed_) ++bucket_start_[bucketOf(entry.first) + 1];
  for (std::size_t b = 0; b < buckets; ++b) bucket_start_[b + 1] += bucket_start_[b];
  entries_.resize(keyed_.size());
  for (const auto& entry : keyed_) {
    // bucket_start_[b] is bucket b's cursor while the entries are placed.
    entries_[bucket_start_[bucketOf(entry.first)]++] = entry;
  }
  // The cursors ended at each bucket's end, which is the next bucket's start: shift them back.
  for (std::size_t b = buckets; b > 0; --b) bucket_start_[b] = bucket_start_[b - 1];
  bucket_start_[0] = 0;
}

void SpatialHash::overlappingPairs(std::vector<std::pair<std::size_t, std::size_t>>& pairs) {
  pairs.clear();
  unordered_.clear();
  if (boxes_ == nullptr) return;
  const std::vector<Box>& boxes = *boxes_;
  const std::size_t buckets = bucket_start_.size() - 1;
  for (std::size_t b = 0; b < buckets; ++b) {
    const std::size_t begin = bucket_start_[b], end = bucket_start_[b + 1];
    for (std::size_t i = begin; i < end; ++i) {
      for (std::size_t j = i + 1; j < end; ++j) {
        if (entries_[i].first != entries_[j].first) continue;  // another cell, same bucket
        const std::size_t a = entries_[i].second, c = entries_[j].second;
        if (a == c || !boxes[a].overlaps(boxes[c])) continue;
        // Two boxes share every cell their intersection covers: the pair is reported in one
        // of them only, the cell of the intersection's low corner, so no pair comes twice.
        const Cell corner = cellOf(boxes[a].low.cwiseMax(boxes[c].low));
        if (key(corner.x, corner.y, corner.z) != entries_[i].first) continue;
        unordered_.emplace_back(std::min(a, c), std::max(a, c));
      }
    }
  }
  for (const std::size_t big : large_) {
    for (std::size_t other = 0; other < boxes.size(); ++other) {
      if (other == big || !(*active_)[other] || !boxes[big].overlaps(boxes[other])) continue;
      const bool other_large = std::find(large_.begin(), large_.end(), other) != large_.end();
      if (other_large && other < big) continue;  // two large boxes: reported once
      unordered_.emplace_back(std::min(big, other), std::max(big, other));
    }
  }
  // Sorted by a counting sort on the first body, then each (short) run on the second.
  first_count_.assign(boxes.size() + 1, 0);
  for (const auto& pair : unordered_) ++first_count_[pair.first + 1];
  for (std::size_t i = 0; i < boxes.size(); ++i) first_count_[i + 1] += first_count_[i];
  pairs.resize(unordered_.size());
  for (const auto& pair : unordered_) pairs[first_count_[pair.first]++] = pair;
  for (std::size_t begin = 0; begin < pairs.size();) {
    std::size_t end = begin + 1;
    while (end < pairs.size() && pairs[end].first == pairs[begin].first) ++end;
    std::sort(pairs.begin() + static_cast<std::ptrdiff_t>(begin),
              pairs.begin() + static_cast<std::ptrdiff_t>(end));
    begin = end;
  }
}

void SpatialHash::query(const Box& box, std::vector<std::size_t>& found) const {
  found.clear();
  if (boxes_ == nullptr) return;
  const std::vector<Box>& boxes = *boxes_;
  const bool small = forEachCell(box, [&](std::uint64_t k) {
    const std::size_t b = bucketOf(k);
    for (std::size_t i = bucket_start_[b]; i < bucket_start_[b + 1]; ++i) {
      if (entries_[i].first == k && boxes[entries_[i].second].overlaps(box)) {
        found.push_back(entries_[i].second);
      }
    }
  });
  if (!small) {  // a huge query box: test every entered box
    for (const auto& entry : entries_) {
      if (boxes[entry.second].overlaps(box)) found.push_back(entry.second);
    }
  }
  for (const std::size_t big : large_) {
    if (boxes[big].overlaps(box)) found.push_back(big);
  }
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
}

}  // namespace collision_response::core
