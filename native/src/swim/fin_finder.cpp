#include "kodawari/swim/fin_finder.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

#include "kodawari/parallel.hpp"

namespace kodawari::swim {

namespace {

constexpr std::size_t kMinVerticesPerThread = 16384;

struct AxisSegment {
  Vec3 start, tangent, side, up;
  Real length = 0, arc0 = 0;
};

// Union-find with path halving; indices are vertex numbers.
struct DisjointSets {
  std::vector<std::int32_t> parent;
  explicit DisjointSets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::int32_t find(std::int32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(std::int32_t a, std::int32_t b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

struct Outline {
  Real r = -1, side = 0, up = 0;  // the outermost point of a sector (r < 0: empty)
};

int slice_of(Real s, int slices) { return std::clamp(static_cast<int>(s * slices), 0, slices - 1); }

int sector_of(Real side, Real up, int sectors) {
  const Real angle = std::atan2(up, side) + kPi;  // [0, 2π]
  return std::clamp(static_cast<int>(angle / (2 * kPi) * sectors), 0, sectors - 1);
}

void add_point(std::vector<Outline>& outline, const FinFinderOptions& o, Real s, Real side, Real up) {
  Outline& cell = outline[static_cast<std::size_t>(slice_of(s, o.slices) * o.sectors + sector_of(side, up, o.sectors))];
  const Real r = std::hypot(side, up);
  if (r > cell.r) cell = {r, side, up};
}

// Axis-aligned ellipse A x² + B y² + C x + D y = 1 fitted to the outline points kept
// by least squares, refitted without the points outside it by more than a bound that
// tightens pass by pass. Returns the core and how many points lie on it (within 10%).
std::pair<SliceCore, int> fit_from(const std::vector<const Outline*>& points, std::vector<char> keep,
                                   const FinFinderOptions& o) {
  SliceCore core;
  constexpr Real kBounds[] = {2.0, 1.6, 1.35, 1.2, 1.15, 1.15};
  for (Real bound : kBounds) {
    Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
    Eigen::Vector4d rhs = Eigen::Vector4d::Zero();
    int used = 0;
    for (std::size_t k = 0; k < points.size(); ++k) {
      if (!keep[k]) continue;
      const Eigen::Vector4d row(points[k]->side * points[k]->side, points[k]->up * points[k]->up, points[k]->side,
                                points[k]->up);
      normal += row * row.transpose();
      rhs += row;
      ++used;
    }
    if (used < 5) break;
    const Eigen::Vector4d x = normal.ldlt().solve(rhs);
    const Real a = x[0], b = x[1];
    if (!(a > 0) || !(b > 0)) break;
    const Real cs = -x[2] / (2 * a), cu = -x[3] / (2 * b);
    const Real g = 1 + a * cs * cs + b * cu * cu;
    if (!(g > 0)) break;
    core.has_core = true;
    core.centre_side = cs;
    core.centre_up = cu;
    core.half_side = std::sqrt(g / a);
    core.half_up = std::sqrt(g / b);
    // A very flat "core" is a fin plate (caudal fin, flukes): the body is its thick middle.
    core.half_side = std::min(core.half_side, o.max_aspect * core.half_up);
    core.half_up = std::min(core.half_up, o.max_aspect * core.half_side);
    bool changed = false;
    for (std::size_t k = 0; k < points.size(); ++k) {
      const Real ds = (points[k]->side - cs) / core.half_side, du = (points[k]->up - cu) / core.half_up;
      const bool inside = std::hypot(ds, du) < bound;
      changed |= (inside != static_cast<bool>(keep[k]));
      keep[k] = inside;
    }
    if (!changed && bound <= Real(1.15)) break;
  }
  int on = 0;
  if (core.has_core) {
    for (const Outline* p : points) {
      const Real rho = std::hypot((p->side - core.centre_side) / core.half_side, (p->up - core.centre_up) / core.half_up);
      on += std::abs(rho - 1) < Real(0.1);
    }
  }
  return {core, on};
}

// The body's core in one slice: of two robust fits, the one more of the outline lies on.
// One starts without the sectors reaching past 1.5 median radii (fins close to the body's
// size, like an eel's, would otherwise stretch it); the other from every sector (a flat
// body's narrow sides reach far past the median, yet are body).
SliceCore fit_core(const std::vector<Outline>& cells, const FinFinderOptions& o) {
  std::vector<const Outline*> points;
  for (const Outline& c : cells) {
    if (c.r >= 0) points.push_back(&c);
  }
  if (static_cast<int>(points.size()) < o.sectors / 2) return SliceCore{};
  std::vector<Real> radii;
  for (const Outline* p : points) radii.push_back(p->r);
  std::nth_element(radii.begin(), radii.begin() + radii.size() / 2, radii.end());
  const Real median = radii[radii.size() / 2];
  std::vector<char> near(points.size());
  for (std::size_t k = 0; k < points.size(); ++k) near[k] = points[k]->r <= Real(1.5) * median;
  const auto trimmed = fit_from(points, near, o);
  const auto whole = fit_from(points, std::vector<char>(points.size(), 1), o);
  return whole.second > trimmed.second ? whole.first : trimmed.first;
}

}  // namespace

void fin_axis_coordinates(const Vec3List& axis, const Vec3& up, const float* vertices, std::size_t begin,
                          std::size_t end, float* out, unsigned threads) {
  if (axis.size() < 2) throw std::invalid_argument("the fin finder's axis needs at least 2 points");
  std::vector<AxisSegment> segments;
  Real total = 0;
  for (std::size_t k = 0; k + 1 < axis.size(); ++k) {
    const Vec3 d = axis[k + 1] - axis[k];
    const Real length = d.norm();
    if (length <= 0) continue;
    AxisSegment seg;
    seg.start = axis[k];
    seg.tangent = d / length;
    Vec3 u = up - up.dot(seg.tangent) * seg.tangent;
    if (u.norm() < 1e-9) u = seg.tangent.unitOrthogonal();
    seg.up = u.normalized();
    seg.side = seg.tangent.cross(seg.up);
    seg.length = length;
    seg.arc0 = total;
    total += length;
    segments.push_back(seg);
  }
  if (segments.empty()) throw std::invalid_argument("the fin finder's axis has no length");
  parallel_for(end - begin, threads, kMinVerticesPerThread, [&](std::size_t lo, std::size_t hi) {
    for (std::size_t i = begin + lo; i < begin + hi; ++i) {
      const Vec3 p(vertices[3 * i], vertices[3 * i + 1], vertices[3 * i + 2]);
      Real best = std::numeric_limits<Real>::infinity();
      const AxisSegment* nearest = &segments.front();
      Real along = 0;
      for (const AxisSegment& seg : segments) {
        const Real t = std::clamp((p - seg.start).dot(seg.tangent), Real(0), seg.length);
        const Real d = (p - seg.start - t * seg.tangent).squaredNorm();
        if (d < best) best = d, nearest = &seg, along = t;
      }
      Vec3 offset = p - nearest->start - along * nearest->tangent;
      offset -= offset.dot(nearest->tangent) * nearest->tangent;  // beyond an end: across only
      out[3 * i] = static_cast<float>((nearest->arc0 + along) / total);
      out[3 * i + 1] = static_cast<float>(offset.dot(nearest->side) / total);
      out[3 * i + 2] = static_cast<float>(offset.dot(nearest->up) / total);
    }
  });
}

std::vector<SliceCore> fin_slice_cores(const float* coordinates, std::size_t count, const std::int32_t* edges,
                                       std::size_t edge_count, const FinFinderOptions& o) {
  if (o.slices < 1 || o.sectors < 8) throw std::invalid_argument("the fin finder needs slices >= 1, sectors >= 8");
  std::vector<Outline> outline(static_cast<std::size_t>(o.slices * o.sectors));
  for (std::size_t i = 0; i < count; ++i) {
    add_point(outline, o, coordinates[3 * i], coordinates[3 * i + 1], coordinates[3 * i + 2]);
  }
  // Long edges (low-poly meshes) are sampled so every sector they cross sees them.
  const Real step = Real(0.5) / o.slices;
  for (std::size_t e = 0; e < edge_count; ++e) {
    const float* a = coordinates + 3 * static_cast<std::size_t>(edges[2 * e]);
    const float* b = coordinates + 3 * static_cast<std::size_t>(edges[2 * e + 1]);
    const Real length = std::sqrt(Real(a[0] - b[0]) * (a[0] - b[0]) + Real(a[1] - b[1]) * (a[1] - b[1]) +
                                  Real(a[2] - b[2]) * (a[2] - b[2]));
    const int pieces = std::min(32, static_cast<int>(std::ceil(length / step)));
    for (int j = 1; j < pieces; ++j) {
      const Real f = Real(j) / pieces;
      add_point(outline, o, a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2]));
    }
  }
  std::vector<SliceCore> cores(static_cast<std::size_t>(o.slices));
  for (int k = 0; k < o.slices; ++k) {
    const auto first = outline.begin() + static_cast<std::ptrdiff_t>(k) * o.sectors;
    cores[static_cast<std::size_t>(k)] = fit_core(std::vector<Outline>(first, first + o.sectors), o);
  }
  return cores;
}

std::vector<std::int8_t> find_fins(const float* coordinates, std::size_t count, const std::int32_t* edges,
                                   std::size_t edge_count, const FinFinderOptions& o) {
  for (std::size_t e = 0; e < 2 * edge_count; ++e) {
    if (edges[e] < 0 || static_cast<std::size_t>(edges[e]) >= count) {
      throw std::invalid_argument("edges holds vertex index " + std::to_string(edges[e]) + ", out of range");
    }
  }
  const std::vector<SliceCore> cores = fin_slice_cores(coordinates, count, edges, edge_count, o);
  std::vector<char> candidate(count, 0);
  for (std::size_t i = 0; i < count; ++i) {
    const Real side = coordinates[3 * i + 1], up = coordinates[3 * i + 2];
    const SliceCore& c = cores[static_cast<std::size_t>(slice_of(coordinates[3 * i], o.slices))];
    if (!c.has_core) {
      candidate[i] = std::hypot(side, up) > o.margin;
      continue;
    }
    const Real ds = side - c.centre_side, du = up - c.centre_up;
    const Real rho = std::hypot(ds / c.half_side, du / c.half_up);
    const Real excess = std::hypot(ds, du) * (1 - 1 / std::max(rho, Real(1e-12)));
    candidate[i] = rho > o.outside && excess > o.margin;
  }
  DisjointSets sets(count);
  for (std::size_t e = 0; e < edge_count; ++e) {
    const std::int32_t a = edges[2 * e], b = edges[2 * e + 1];
    if (candidate[a] && candidate[b]) sets.join(a, b);
  }
  struct Part {
    std::size_t size = 0;
    Real s = 0, side = 0, up = 0, s_max = 0;
  };
  std::vector<Part> parts(count);
  for (std::size_t i = 0; i < count; ++i) {
    if (!candidate[i]) continue;
    Part& p = parts[static_cast<std::size_t>(sets.find(static_cast<std::int32_t>(i)))];
    ++p.size;
    p.s += coordinates[3 * i];
    p.side += coordinates[3 * i + 1];
    p.up += coordinates[3 * i + 2];
    p.s_max = std::max<Real>(p.s_max, coordinates[3 * i]);
  }
  std::vector<std::int8_t> kind_of_root(count, 0);
  for (std::size_t r = 0; r < count; ++r) {
    const Part& p = parts[r];
    if (p.size < std::max<std::size_t>(o.min_vertices, 1)) continue;
    const Real s = p.s / p.size;
    const SliceCore& c = cores[static_cast<std::size_t>(slice_of(s, o.slices))];
    const Real side = p.side / p.size - (c.has_core ? c.centre_side : 0);
    const Real up = p.up / p.size - (c.has_core ? c.centre_up : 0);
    FinKind kind;
    if (p.s_max >= Real(0.97) && s > Real(0.75)) {
      kind = FinKind::Caudal;  // reaches the tail tip from behind the body
    } else if (up > std::abs(side)) {
      kind = FinKind::Dorsal;
    } else if (up < -Real(0.75) * std::abs(side)) {
      kind = s < Real(0.52) ? FinKind::Pelvic : FinKind::Anal;
    } else {
      kind = FinKind::Pectoral;
    }
    kind_of_root[r] = static_cast<std::int8_t>(kind);
  }
  std::vector<std::int8_t> kinds(count, 0);
  for (std::size_t i = 0; i < count; ++i) {
    if (candidate[i]) kinds[i] = kind_of_root[static_cast<std::size_t>(sets.find(static_cast<std::int32_t>(i)))];
  }
  return kinds;
}

}  // namespace kodawari::swim
