#include "kodawari/swim/fin_reach.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <queue>
#include <stdexcept>
#include <string>
#include <utility>

#include "kodawari/parallel.hpp"

namespace kodawari::swim {

namespace {

constexpr std::size_t kLeafSize = 8;

// A k-d tree over the cloud, stored implicitly: `order` is the cloud's indices
// arranged so that every range [begin, end) splits at its middle on `axis_of` its depth.
class PointTree {
 public:
  PointTree(const float* cloud, std::size_t count) : cloud_(cloud), order_(count) {
    std::iota(order_.begin(), order_.end(), std::uint32_t(0));
    build(0, count, 0);
  }

  // Distance to the nearest cloud point, or +inf when none is closer than `within`.
  Real nearest(const Vec3& p, Real within = std::numeric_limits<Real>::infinity()) const {
    Real best2 = within * within;
    const Real bound = best2;
    search(p, 0, order_.size(), 0, best2);
    return best2 < bound ? std::sqrt(best2) : std::numeric_limits<Real>::infinity();
  }

 private:
  Real coord(std::uint32_t j, int axis) const { return cloud_[3 * static_cast<std::size_t>(j) + axis]; }

  void build(std::size_t begin, std::size_t end, int depth) {
    if (end - begin <= kLeafSize) return;
    const int axis = depth % 3;
    const std::size_t mid = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                     [&](std::uint32_t a, std::uint32_t b) { return coord(a, axis) < coord(b, axis); });
    build(begin, mid, depth + 1);
    build(mid + 1, end, depth + 1);
  }

  void search(const Vec3& p, std::size_t begin, std::size_t end, int depth, Real& best2) const {
    if (end - begin <= kLeafSize) {
      for (std::size_t q = begin; q < end; ++q) {
        const std::uint32_t j = order_[q];
        const Vec3 c(coord(j, 0), coord(j, 1), coord(j, 2));
        best2 = std::min(best2, (c - p).squaredNorm());
      }
      return;
    }
    const int axis = depth % 3;
    const std::size_t mid = begin + (end - begin) / 2;
    const std::uint32_t j = order_[mid];
    const Vec3 c(coord(j, 0), coord(j, 1), coord(j, 2));
    best2 = std::min(best2, (c - p).squaredNorm());
    const Real gap = p[axis] - c[axis];
    // Near side first; the far side only while the splitting plane is closer than the best.
    if (gap < 0) {
      search(p, begin, mid, depth + 1, best2);
      if (gap * gap < best2) search(p, mid + 1, end, depth + 1, best2);
    } else {
      search(p, mid + 1, end, depth + 1, best2);
      if (gap * gap < best2) search(p, begin, mid, depth + 1, best2);
    }
  }

  const float* cloud_;
  std::vector<std::uint32_t> order_;
};

}  // namespace

std::vector<Real> nearest_distances(const float* points, std::size_t count, const float* cloud,
                                    std::size_t cloud_count, unsigned threads) {
  std::vector<Real> out(count, std::numeric_limits<Real>::infinity());
  if (cloud_count == 0 || count == 0) return out;
  const PointTree tree(cloud, cloud_count);
  parallel_for(count, threads, 4096, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      out[i] = tree.nearest(Vec3(points[3 * i], points[3 * i + 1], points[3 * i + 2]));
    }
  });
  return out;
}

std::vector<Real> fin_reach(const float* vertices, std::size_t count, const std::int32_t* edges,
                            std::size_t edge_count, const std::uint8_t* in_fin, Real seed_radius,
                            std::vector<std::int64_t>* source, unsigned threads, const float* squash,
                            Real squash_factor) {
  if (!(squash_factor >= 0 && squash_factor <= 1)) throw std::invalid_argument("squash_factor must be in [0, 1]");
  for (std::size_t e = 0; e < 2 * edge_count; ++e) {
    if (edges[e] < 0 || static_cast<std::size_t>(edges[e]) >= count) {
      throw std::invalid_argument("edges holds vertex index " + std::to_string(edges[e]) + ", out of range");
    }
  }
  const Real inf = std::numeric_limits<Real>::infinity();
  std::vector<Real> reach(count, Real(0));
  std::vector<std::int64_t> from(count);
  std::iota(from.begin(), from.end(), std::int64_t(0));
  std::vector<float> body;
  std::vector<std::size_t> fins;
  for (std::size_t i = 0; i < count; ++i) {
    if (in_fin[i]) {
      fins.push_back(i);
      reach[i] = inf;
    } else {
      body.insert(body.end(), vertices + 3 * i, vertices + 3 * i + 3);
    }
  }
  if (fins.empty() || body.empty()) return reach;
  auto point = [&](std::size_t i) { return Vec3(vertices[3 * i], vertices[3 * i + 1], vertices[3 * i + 2]); };
  const PointTree tree(body.data(), body.size() / 3);
  // Seeds: fin vertices on the body (a root row sitting on body vertices) ...
  parallel_for(fins.size(), threads, 1024, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) reach[fins[k]] = tree.nearest(point(fins[k]), seed_radius);
  });
  // ... and fin vertices joined to the body by an edge (a welded fin).
  // An edge's length with its part in each end's squash subspace (projector P) counted
  // squash_factor times, the shorter of the two ends' metrics (so the reach's growth in
  // the subspace is bounded at both ends); never below squash_factor · length.
  const Real shrink = Real(1) - squash_factor * squash_factor;
  auto metric2 = [&](const Vec3& e, std::size_t i) {
    const float* p = squash + 9 * i;
    Real squashed = 0;
    for (int r = 0; r < 3; ++r) squashed += e[r] * (p[3 * r] * e[0] + p[3 * r + 1] * e[1] + p[3 * r + 2] * e[2]);
    const Real length2 = e.squaredNorm();
    return std::clamp(length2 - shrink * squashed, squash_factor * squash_factor * length2, length2);
  };
  auto edge_length = [&](std::size_t a, std::size_t b) {
    const Vec3 e = point(a) - point(b);
    if (squash == nullptr) return e.norm();
    return std::sqrt(std::min(metric2(e, a), metric2(e, b)));
  };
  std::vector<std::vector<std::pair<std::int32_t, Real>>> links(count);
  for (std::size_t e = 0; e < edge_count; ++e) {
    const std::int32_t a = edges[2 * e], b = edges[2 * e + 1];
    const Real length = edge_length(static_cast<std::size_t>(a), static_cast<std::size_t>(b));
    if (in_fin[a] && in_fin[b]) {
      links[a].push_back({b, length});
      links[b].push_back({a, length});
    } else if (in_fin[a] && length < reach[a]) {
      reach[a] = length;
      from[a] = b;
    } else if (in_fin[b] && length < reach[b]) {
      reach[b] = length;
      from[b] = a;
    }
  }
  // Dijkstra over the fin's own edges: the reach is the path length across the fin.
  using Item = std::pair<Real, std::int32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (std::size_t i : fins) {
    if (reach[i] < inf) queue.push({reach[i], static_cast<std::int32_t>(i)});
  }
  while (!queue.empty()) {
    const auto [d, i] = queue.top();
    queue.pop();
    if (d > reach[i]) continue;
    for (const auto& [j, length] : links[i]) {
      if (d + length < reach[j]) {
        reach[j] = d + length;
        from[j] = from[i];
        queue.push({reach[j], j});
      }
    }
  }
  // A fin part with no way to the body (a loose plate): its straight distance.
  for (std::size_t i : fins) {
    if (reach[i] == inf) reach[i] = tree.nearest(point(i));
  }
  if (source != nullptr) *source = std::move(from);
  return reach;
}

}  // namespace kodawari::swim
