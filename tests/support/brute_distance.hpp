// Brute-force distances for tests of error bounds (cluster DAG, HLOD): exact point-to-surface distance over
// every triangle, and the points of a mesh to measure from. Slow (O(samples x triangles)); small meshes only.
#pragma once

#include <glm/glm.hpp>
#include <vector>

#include "core/mesh.hpp"

namespace lodstream::test {

// Distance from p to triangle abc (Ericson, Real-Time Collision Detection, 5.1.5).
double point_triangle_distance(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c);

// Distance from p to the nearest triangle of `meshes`; +inf when they have none.
double distance_to(const glm::dvec3& p, const std::vector<const Mesh*>& meshes);

// Points of a mesh to test distances from: vertices, triangle centroids and edge midpoints.
std::vector<glm::dvec3> samples(const Mesh& m);

}  // namespace lodstream::test
