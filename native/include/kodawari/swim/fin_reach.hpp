// How far each fin vertex stands from the body (docs/algorithms.md §2.4):
// the distance to the nearest body vertex, which is 0 on the fin's root row and
// grows toward its rim. The fin motion fades in over it, so the root stays on the body.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kodawari/common.hpp"

namespace kodawari::swim {

// For each of the `count` points (float xyz triples), the distance to the nearest of
// the `cloud_count` cloud points, by a k-d tree over the cloud: O((count +
// cloud_count) · log cloud_count) instead of O(count · cloud_count). Empty cloud: +inf.
std::vector<Real> nearest_distances(const float* points, std::size_t count, const float* cloud,
                                    std::size_t cloud_count, unsigned threads = 0);

// How far each fin vertex (in_fin[i] != 0) stands from the body, measured ACROSS the
// fin: shortest path along the fin's own edges from where it meets the body (a fin
// vertex joined by an edge to a body vertex, or lying within seed_radius of one).
// A path across the fin, not a straight line, so the fade follows the surface and
// two neighbouring vertices never get far-apart values. Body vertices get 0; a fin
// part with no path to the body gets its straight distance to the nearest body vertex.
// `source` (optional) receives, per vertex, the vertex its path starts from: the body
// vertex (or seed fin vertex) at the fin's root below it; itself for body vertices.
// `squash` (optional, count row-major 3×3 float projectors, zero = none): per vertex, the
// directions its part's motion moves it in, across the fin's lines (fish/fins.py: the
// swing direction, or everything across the outward direction for a fin that feathers);
// an edge's extent in them counts only `squash_factor` times (in the shorter of its two
// ends' metrics), so the reach grows at most squash_factor per unit length along the
// motion (docs/algorithms.md §2.4: a reach growing along the swing, as across a thin
// fin's two faces or a fan-shaped tail, stretched edges 1.6× at 0.6 rad).
std::vector<Real> fin_reach(const float* vertices, std::size_t count, const std::int32_t* edges,
                            std::size_t edge_count, const std::uint8_t* in_fin, Real seed_radius,
                            std::vector<std::int64_t>* source = nullptr, unsigned threads = 0,
                            const float* squash = nullptr, Real squash_factor = 1);

// The reach's largest growth across a swinging fin's lines (per unit length): keeps every
// edge under 1.5× at 0.6 rad with room for the body's own stretch (docs/algorithms.md §2.4).
constexpr Real kSwingReachSlope = 0.6;

}  // namespace kodawari::swim
