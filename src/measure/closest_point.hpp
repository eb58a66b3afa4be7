// Exact closest point on a triangle to a point in space.
#pragma once

#include <glm/glm.hpp>

namespace lodstream {

// The point of triangle (a, b, c) nearest to p: Ericson, "Real-Time Collision Detection" (2005), §5.1.5
// ClosestPtPointTriangle — classify p against the Voronoi regions of the three vertices, three edges and the
// face using barycentric dot products, then project onto that feature. A degenerate (zero-area) triangle
// gives the nearest point of its three edges. Cost: O(1), about 30 multiply-adds; float precision.
glm::vec3 closest_point_on_triangle(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b,
                                    const glm::vec3& c);

}  // namespace lodstream
