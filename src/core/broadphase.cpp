#include "collision_response/core/broadphase.h"

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
  const Cell low = cellOf(box.low), high = cellOf(box.high);
  const std::int64_t count = (high.x - low.x + 1) * (high.y - low.y + 1) * (high.z - low.z + 1);
  if (count > static_cast<std::int64_t>(kMaxCells) || count <= 0) return false;
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
  entries_.clear();
  large_.clear();
  std::vector<double> extents;
  extents.reserve(boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    if (active[i]) extents.push_back((boxes[i].high - boxes[i].low).maxCoeff());
  }
  if (extents.empty()) return;
  std::nth_element(extents.begin(), extents.begin() + extents.size() / 2, extents.end());
  const double median = extents[extents.size() / 2];
  cell_size_ = median > 0 && std::isfinite(median) ? median : 1.0;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    if (!active[i]) continue;
    const std::size_t before = entries_.size();
    if (!forEachCell(boxes[i], [&](std::uint64_t k) { entries_.emplace_back(k, i); })) {
      entries_.resize(before);
      large_.push_back(i);
    }
  }
  std::sort(entries_.begin(), entries_.end());
}

void SpatialHash::overlappingPairs(std::vector<std::pair<std::size_t, std::size_t>>& pairs) {
  pairs.clear();
  if (boxes_ == nullptr) return;
  const std::vector<Box>& boxes = *boxes_;
  for (std::size_t begin = 0; begin < entries_.size();) {
    std::size_t end = begin;
    while (end < entries_.size() && entries_[end].first == entries_[begin].first) ++end;
    for (std::size_t i = begin; i < end; ++i) {
      for (std::size_t j = i + 1; j < end; ++j) {
        const std::size_t a = entries_[i].second, b = entries_[j].second;
        if (a != b && boxes[a].overlaps(boxes[b]))
          pairs.emplace_back(std::min(a, b), std::max(a, b));
      }
    }
    begin = end;
  }
  for (const std::size_t big : large_) {
    for (std::size_t other = 0; other < boxes.size(); ++other) {
      if (other != big && (*active_)[other] && boxes[big].overlaps(boxes[other])) {
        pairs.emplace_back(std::min(big, other), std::max(big, other));
      }
    }
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
}

void SpatialHash::query(const Box& box, std::vector<std::size_t>& found) const {
  found.clear();
  if (boxes_ == nullptr) return;
  const std::vector<Box>& boxes = *boxes_;
  const bool small = forEachCell(box, [&](std::uint64_t k) {
    auto it = std::lower_bound(entries_.begin(), entries_.end(), std::make_pair(k, std::size_t{0}));
    for (; it != entries_.end() && it->first == k; ++it) {
      if (boxes[it->second].overlaps(box)) found.push_back(it->second);
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
