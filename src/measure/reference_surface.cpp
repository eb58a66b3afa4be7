#include "measure/reference_surface.hpp"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "measure/closest_point.hpp"
#include "measure/surface_sampling.hpp"
#include "measure/world_surface.hpp"

namespace lodstream {

namespace {
// One Embree device for the whole process: creating one costs milliseconds, and reference surfaces are built
// many times by tests. It is intentionally never released (Embree's worker threads are TBB's, which outlive
// it anyway).
RTCDevice shared_device() {
  static RTCDevice device = [] {
    RTCDevice d = rtcNewDevice("verbose=0");
    if (!d)
      throw Error("Embree: cannot create a device (error " + std::to_string(rtcGetDeviceError(nullptr)) +
                  ")");
    return d;
  }();
  return device;
}

void check_device(const char* what) {
  RTCError e = rtcGetDeviceError(shared_device());
  if (e != RTC_ERROR_NONE)
    throw Error(std::string("Embree: ") + what + " failed (error " + std::to_string(e) + ")");
}

constexpr float infinity = std::numeric_limits<float>::infinity();
}  // namespace

struct ReferenceSurface::Impl {
  RTCScene scene = nullptr;
  const glm::vec3* positions = nullptr;  // Embree's vertex buffer (owned by the scene's geometry)
  const uint32_t* indices = nullptr;     // Embree's index buffer, three per triangle
  size_t triangles = 0;
  Bounds bounds;
  float slack = 0;  // absolute widening of query radii derived from a neighbour (rounding of the bound)

  ~Impl() {
    if (scene) rtcReleaseScene(scene);
  }

  // The BVH of a world-space surface; `what` names it in errors.
  static std::unique_ptr<Impl> build(const Mesh& world, const std::string& what);

  // A previous query's answer: d(p) <= hint.distance + |p − hint.point| by the triangle inequality, which
  // bounds the search radius of the next nearby query (consecutive samples are close, so most of the BVH is
  // pruned).
  struct Hint {
    glm::vec3 point{0.0f};
    float distance = infinity;
  };

  struct QueryState {
    const Impl* impl;
    Closest best;
    bool found = false;
  };

  // Embree calls this for each triangle whose box meets the query sphere; shrinking the radius prunes the
  // rest.
  static bool visit_triangle(RTCPointQueryFunctionArguments* args) {
    auto* state = static_cast<QueryState*>(args->userPtr);
    const Impl& self = *state->impl;
    const uint32_t* v = self.indices + 3 * size_t(args->primID);
    const glm::vec3 p(args->query->x, args->query->y, args->query->z);
    const glm::vec3 q =
        closest_point_on_triangle(p, self.positions[v[0]], self.positions[v[1]], self.positions[v[2]]);
    const float d = glm::length(p - q);
    if (!(d < args->query->radius)) return false;
    args->query->radius = d;
    state->best = {q, d, args->primID};
    state->found = true;
    return true;
  }

  bool query(const glm::vec3& p, float radius, Closest& out) const {
    RTCPointQuery q;
    q.x = p.x;
    q.y = p.y;
    q.z = p.z;
    q.time = 0.0f;
    q.radius = radius;
    RTCPointQueryContext context;
    rtcInitPointQueryContext(&context);
    QueryState state{this, {}, false};
    rtcPointQuery(scene, &q, &context, &visit_triangle, &state);
    out = state.best;
    return state.found;
  }

  Closest closest(const glm::vec3& p, Hint& hint) const {
    Closest c;
    const float bound = (hint.distance + glm::length(p - hint.point)) * 1.0001f + slack;
    if (!(std::isfinite(bound) && query(p, bound, c))) query(p, infinity, c);
    hint = {p, c.distance};
    return c;
  }
};

std::unique_ptr<ReferenceSurface::Impl> ReferenceSurface::Impl::build(const Mesh& world,
                                                                      const std::string& what) {
  if (world.triangle_count() == 0) throw Error(what + " has no triangles");
  RTCDevice device = shared_device();
  auto impl = std::make_unique<ReferenceSurface::Impl>();
  impl->triangles = world.triangle_count();
  impl->bounds = world.bounds();
  impl->slack = 1e-6f * std::max(impl->bounds.diagonal(), std::numeric_limits<float>::min());
  impl->scene = rtcNewScene(device);
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  check_device("creating the scene");
  // Embree's own buffers are padded as its SIMD loads need; the callback reads them back.
  auto* positions = static_cast<glm::vec3*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, sizeof(glm::vec3), world.positions.size()));
  auto* indices = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), impl->triangles));
  if (!positions || !indices) {
    rtcReleaseGeometry(geometry);
    check_device("allocating buffers");
    throw Error("Embree: allocating buffers failed");
  }
  std::memcpy(positions, world.positions.data(), world.positions.size() * sizeof(glm::vec3));
  std::memcpy(indices, world.indices.data(), world.indices.size() * sizeof(uint32_t));
  impl->positions = positions;
  impl->indices = indices;
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(impl->scene, geometry);
  rtcReleaseGeometry(geometry);  // the scene holds it
  rtcCommitScene(impl->scene);
  check_device("building the BVH");
  return impl;
}

ReferenceSurface::ReferenceSurface(const Mesh& mesh, const glm::mat4& transform) {
  Mesh world;
  append_world_surface(mesh, transform, world, "reference mesh");
  impl_ = Impl::build(world, "reference mesh");
}

ReferenceSurface::ReferenceSurface(const Scene& scene)
    : impl_(Impl::build(world_surface(scene), "reference scene")) {}

ReferenceSurface::~ReferenceSurface() = default;
ReferenceSurface::ReferenceSurface(ReferenceSurface&&) noexcept = default;
ReferenceSurface& ReferenceSurface::operator=(ReferenceSurface&&) noexcept = default;

size_t ReferenceSurface::triangle_count() const {
  return impl_->triangles;
}
Bounds ReferenceSurface::bounds() const {
  return impl_->bounds;
}

ReferenceSurface::Closest ReferenceSurface::closest(const glm::vec3& p) const {
  Impl::Hint none;
  return impl_->closest(p, none);
}

void ReferenceSurface::distances(std::span<const glm::vec3> points, std::span<float> out) const {
  if (out.size() != points.size())
    throw Error("distances: " + std::to_string(points.size()) + " points but room for " +
                std::to_string(out.size()));
  tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), 1024),
                    [&](const tbb::blocked_range<size_t>& r) {
                      Impl::Hint hint;
                      for (size_t i = r.begin(); i != r.end(); ++i)
                        out[i] = impl_->closest(points[i], hint).distance;
                    });
}

OneSidedDistance ReferenceSurface::distance_from(const Mesh& surface, const DistanceOptions& options) const {
  const size_t triangles = surface.triangle_count();
  if (triangles == 0) throw Error("the measured mesh has no triangles");
  // Vertices referenced by a triangle are samples too (unreferenced ones are not on the surface).
  std::vector<uint8_t> referenced(surface.positions.size(), 0);
  for (size_t i = 0; i < 3 * triangles; ++i) {
    const uint32_t v = surface.indices[i];
    if (v >= surface.positions.size())
      throw Error("the measured mesh's triangle " + std::to_string(i / 3) + " references vertex " +
                  std::to_string(v) + " of " + std::to_string(surface.positions.size()));
    referenced[v] = 1;
  }
  for (size_t v = 0; v < surface.positions.size(); ++v)
    if (referenced[v] && !(std::isfinite(surface.positions[v].x) && std::isfinite(surface.positions[v].y) &&
                           std::isfinite(surface.positions[v].z)))
      throw Error("the measured mesh's vertex " + std::to_string(v) + " has a non-finite position");

  struct Sums {
    double max = 0;   // max of d
    double sum = 0;   // Σ w·d
    double sum2 = 0;  // Σ w·d²
    size_t count = 0;
  };
  auto join = [](Sums a, const Sums& b) {
    a.max = std::max(a.max, b.max);
    a.sum += b.sum;
    a.sum2 += b.sum2;
    a.count += b.count;
    return a;
  };

  const SurfaceSampler sampler(surface, options.samples ? options.samples : default_area_samples(triangles),
                               options.seed);
  // A fixed split (simple partitioner) and a fixed join order make the floating-point sums reproducible.
  const Sums area = tbb::parallel_deterministic_reduce(
      tbb::blocked_range<size_t>(0, triangles, 256), Sums{},
      [&](const tbb::blocked_range<size_t>& r, Sums s) {
        std::vector<glm::vec3> points;
        Impl::Hint hint;
        for (size_t t = r.begin(); t != r.end(); ++t) {
          sampler.sample_triangle(t, points);
          const double w = sampler.triangle_area(t) / double(points.size());
          for (const glm::vec3& p : points) {
            const double d = impl_->closest(p, hint).distance;
            s.max = std::max(s.max, d);
            s.sum += w * d;
            s.sum2 += w * d * d;
          }
          s.count += points.size();
        }
        return s;
      },
      join);
  const Sums vertices = tbb::parallel_deterministic_reduce(
      tbb::blocked_range<size_t>(0, surface.positions.size(), 1024), Sums{},
      [&](const tbb::blocked_range<size_t>& r, Sums s) {
        Impl::Hint hint;
        for (size_t v = r.begin(); v != r.end(); ++v) {
          if (!referenced[v]) continue;
          s.max = std::max(s.max, double(impl_->closest(surface.positions[v], hint).distance));
          ++s.count;
        }
        return s;
      },
      join);

  OneSidedDistance result;
  result.area = sampler.total_area();
  result.max = std::max(area.max, vertices.max);
  result.mean = result.area > 0 ? area.sum / result.area : 0.0;
  result.rms = result.area > 0 ? std::sqrt(area.sum2 / result.area) : 0.0;
  result.samples = area.count + vertices.count;
  return result;
}

}  // namespace lodstream
