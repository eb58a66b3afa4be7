// Floating-cell vertex clustering: see cluster.hpp. Hand-written: meshoptimizer 0.18 has no clustering
// simplifier (meshopt_simplifySloppy is a uniform grid without locks or a bound) and OpenMesh has none.
#include "simplify/cluster.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>

#include <glm/gtc/type_precision.hpp>

#include "simplify/quadric.hpp"

namespace lodstream::simplify {
namespace {

constexpr uint32_t kNone = UINT32_MAX;

struct Outcome {
  double rho = 0;
  size_t triangles = 0;
  double bound = INFINITY;  // normalized units
  bool valid = false;       // some triangles kept, no locked vertex lost
  std::vector<uint32_t> cluster, tris;
  std::vector<glm::dvec3> rep;
  std::vector<uint32_t> leader;
  std::vector<double> error;
  std::vector<uint8_t> used;
};

class Clusterer {
 public:
  Clusterer(const Mesh& m, const Options& o, const std::vector<float>& prior)
      : in_(m), opt_(o), prior_(prior) {
    const size_t n = m.vertex_count();
    Bounds box = m.bounds();
    origin_ = box.empty() ? glm::dvec3(0.0) : glm::dvec3(box.min);
    scale_ = box.empty() ? 1.0 : std::max(1e-30, double(box.diagonal()));
    pos_.resize(n);
    for (size_t v = 0; v < n; ++v) pos_[v] = (glm::dvec3(m.positions[v]) - origin_) / scale_;
    locked_.assign(n, 0);
    for (size_t v = 0; v < n && v < o.locked.size(); ++v) locked_[v] = o.locked[v] != 0;
    // Valid triangles, vertex quadrics (area-weighted face planes) and grades.
    std::vector<glm::dvec3> mean(n, glm::dvec3(0.0));
    std::vector<double> min_dot(n, 1.0);
    std::vector<glm::dvec3> normals;
    quadric_.assign(n, Quadric{});
    for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
      uint32_t a = m.indices[t], b = m.indices[t + 1], c = m.indices[t + 2];
      if (a >= n || b >= n || c >= n || a == b || b == c || a == c) continue;
      tris_.insert(tris_.end(), {a, b, c});
      glm::dvec3 nn = glm::cross(pos_[b] - pos_[a], pos_[c] - pos_[a]);
      double len = glm::length(nn);
      normals.push_back(len > 0 ? nn / len : glm::dvec3(0.0));
      if (len > 0) {  // each corner's plane relative to its own position (quadric_)
        const glm::dvec3 un = nn / len;
        for (uint32_t v : {a, b, c}) {
          quadric_[v].add_plane(glm::vec3(un), -float(glm::dot(un, pos_[a] - pos_[v])), float(0.5 * len));
          mean[v] += nn;
        }
      }
    }
    referenced_.assign(n, 0);
    for (size_t t = 0; t < tris_.size() / 3; ++t)
      for (int k = 0; k < 3; ++k) {
        uint32_t v = tris_[3 * t + k];
        referenced_[v] = 1;
        double l = glm::length(mean[v]);
        if (l > 0) min_dot[v] = std::min(min_dot[v], glm::dot(normals[t], mean[v] / l));
      }
    for (uint32_t v = 0; v < n; ++v)
      if (referenced_[v]) order_.push_back(v);
    // Grade (Low & Tan's importance): locked first, then the spread of the face normals around the vertex.
    auto grade = [&](uint32_t v) { return locked_[v] ? 3.0 : 1.0 - min_dot[v]; };
    std::stable_sort(order_.begin(), order_.end(),
                     [&](uint32_t x, uint32_t y) { return grade(x) > grade(y); });
  }

  size_t input_triangles() const { return tris_.size() / 3; }

  Outcome run(double rho) const {
    Outcome o;
    o.rho = rho;
    const size_t n = pos_.size();
    // Uniform grid of cell size rho over the referenced vertices: (cell key, vertex) sorted.
    auto cell_of = [&](const glm::dvec3& p) {
      return glm::i64vec3(std::floor(p.x / rho), std::floor(p.y / rho), std::floor(p.z / rho));
    };
    auto key = [](glm::i64vec3 c) {
      return (uint64_t(c.x & 0x1FFFFF) << 42) | (uint64_t(c.y & 0x1FFFFF) << 21) | uint64_t(c.z & 0x1FFFFF);
    };
    std::vector<std::pair<uint64_t, uint32_t>> grid;
    grid.reserve(order_.size());
    for (uint32_t v : order_) grid.push_back({key(cell_of(pos_[v])), v});
    std::sort(grid.begin(), grid.end());
    o.cluster.assign(n, kNone);
    for (uint32_t v : order_) {
      if (o.cluster[v] != kNone) continue;
      const uint32_t c = uint32_t(o.leader.size());
      o.leader.push_back(v);
      o.cluster[v] = c;
      const glm::i64vec3 cv = cell_of(pos_[v]);
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            uint64_t k = key(cv + glm::i64vec3(dx, dy, dz));
            auto it = std::lower_bound(grid.begin(), grid.end(), std::make_pair(k, 0u));
            for (; it != grid.end() && it->first == k; ++it) {
              uint32_t u = it->second;
              if (o.cluster[u] == kNone && !locked_[u] && glm::distance(pos_[u], pos_[v]) <= rho)
                o.cluster[u] = c;
            }
          }
    }
    // Representatives: the quadric optimum of the members, if within rho of the leader. Each member's
    // quadric is shifted to the leader's position, so x is relative to it.
    const size_t nc = o.leader.size();
    std::vector<Reduced> q(nc);
    for (uint32_t v : order_) q[o.cluster[v]].add(quadric_[v], pos_[o.leader[o.cluster[v]]] - pos_[v]);
    o.rep.resize(nc);
    for (size_t c = 0; c < nc; ++c) {
      const glm::dvec3 lp = pos_[o.leader[c]];
      glm::dvec3 x;
      o.rep[c] = !locked_[o.leader[c]] && q[c].solve(x) && glm::length(x) <= rho ? lp + x : lp;
    }
    // Triangles mapped to clusters: drop repeated clusters and duplicates (same cyclic order).
    const size_t T = tris_.size() / 3;
    std::vector<uint8_t> kept(T, 0);
    std::vector<std::array<uint32_t, 4>> mapped;
    for (size_t t = 0; t < T; ++t) {
      uint32_t a = o.cluster[tris_[3 * t]], b = o.cluster[tris_[3 * t + 1]], c = o.cluster[tris_[3 * t + 2]];
      if (a == b || b == c || a == c) continue;
      kept[t] = 1;
      if (b < a && b < c) std::tie(a, b, c) = std::make_tuple(b, c, a);
      if (c < a && c < b) std::tie(a, b, c) = std::make_tuple(c, a, b);
      mapped.push_back({a, b, c, uint32_t(t)});
    }
    std::sort(mapped.begin(), mapped.end());
    o.used.assign(nc, 0);
    for (size_t i = 0; i < mapped.size(); ++i) {
      if (i > 0 && std::equal(mapped[i].begin(), mapped[i].begin() + 3, mapped[i - 1].begin())) continue;
      o.tris.insert(o.tris.end(), {mapped[i][0], mapped[i][1], mapped[i][2]});
      o.used[mapped[i][0]] = o.used[mapped[i][1]] = o.used[mapped[i][2]] = 1;
    }
    o.triangles = o.tris.size() / 3;
    if (o.triangles == 0) return o;  // invalid: nothing to be near
    for (uint32_t v : order_)        // a locked vertex whose triangles all degenerated: too coarse
      if (locked_[v] && !o.used[o.cluster[v]]) return o;
    // Errors charged per input triangle (cluster.hpp).
    o.error.assign(nc, 0.0);
    std::vector<uint32_t> used_list;
    for (uint32_t c = 0; c < nc; ++c)
      if (o.used[c]) used_list.push_back(c);
    for (size_t t = 0; t < T; ++t) {
      double d = 0;
      uint32_t cs[3];
      for (int k = 0; k < 3; ++k) {
        uint32_t v = tris_[3 * t + k];
        cs[k] = o.cluster[v];
        d = std::max(d,
                     glm::distance(pos_[v], o.rep[cs[k]]) + (v < prior_.size() ? prior_[v] / scale_ : 0.0));
      }
      if (kept[t]) {
        for (uint32_t c : cs) o.error[c] = std::max(o.error[c], d);
        continue;
      }
      uint32_t u = kNone;
      for (uint32_t c : cs)
        if (o.used[c]) u = c;
      if (u == kNone) {  // the image vanished: charge the nearest used representative (rare: small parts)
        double best = INFINITY;
        for (uint32_t c : used_list)
          if (double e = glm::distance(o.rep[c], o.rep[cs[0]]); e < best) best = e, u = c;
      }
      double extra = 0;
      for (uint32_t c : cs) extra = std::max(extra, glm::distance(o.rep[c], o.rep[u]));
      o.error[u] = std::max(o.error[u], d + extra);
    }
    o.bound = 0;
    for (uint32_t c : used_list) o.bound = std::max(o.bound, o.error[c]);
    o.valid = true;
    return o;
  }

  Result output(const Outcome& o) const {
    Result r;
    r.input_triangles = in_.triangle_count();
    Mesh& m = r.mesh;
    m.material = in_.material;
    std::vector<uint32_t> index(o.leader.size(), kNone);
    const double slack = 1e-6 * scale_;  // float rounding of representatives
    for (uint32_t c : o.tris) {
      if (index[c] != kNone) continue;
      index[c] = uint32_t(m.positions.size());
      const uint32_t l = o.leader[c];
      m.positions.push_back(locked_[l] ? in_.positions[l] : glm::vec3(o.rep[c] * scale_ + origin_));
      if (in_.has_normals()) m.normals.push_back(in_.normals[l]);
      if (in_.has_uvs()) m.uvs.push_back(in_.uvs[l]);
      if (in_.has_colors()) m.colors.push_back(in_.colors[l]);
      r.vertex_error.push_back(float(o.error[c] * scale_ * (1 + 1e-5) + slack));
    }
    for (uint32_t c : o.tris) m.indices.push_back(index[c]);
    // The union of both boxes bounds the distance between the two surfaces; the prior error adds to it
    // (triangle inequality) when the input carries one.
    Bounds both = in_.bounds();
    both.add(m.bounds());
    float prior = 0.0f;
    for (float e : prior_) prior = std::max(prior, e);
    const float cap = float((double(both.diagonal()) + prior) * (1 + 1e-6));
    for (float& e : r.vertex_error) {
      e = std::min(e, cap);
      r.error_bound = std::max(r.error_bound, double(e));
    }
    return r;
  }

  double scale() const { return scale_; }

 private:
  const Mesh& in_;
  const Options& opt_;
  const std::vector<float>& prior_;
  glm::dvec3 origin_{0.0};
  double scale_ = 1.0;  // bounding-box diagonal: positions are normalized by it
  std::vector<glm::dvec3> pos_;
  std::vector<uint8_t> locked_, referenced_;
  // Per vertex, its faces' planes relative to its own position: relative to the model's corner the float
  // terms are about W and cancel to W dist^2, which rounding (1e-7 W) drowns at fine cell sizes.
  std::vector<Quadric> quadric_;
  std::vector<uint32_t> tris_, order_;
};

}  // namespace

Result cluster_mesh(const Mesh& mesh, const Options& options, const std::vector<float>& prior_error) {
  Clusterer cl(mesh, options, prior_error);
  const double max_error = options.max_error / (cl.scale() * (1 + 2e-5)) - 1e-6;
  const size_t target = options.target_triangles;
  // Geometric bisection of rho over [1e-6, 1] diagonals: the smallest rho whose count meets the target,
  // among those within the error limit; else the fewest triangles within it.
  Outcome best, fewest;
  double lo = 1e-6, hi = 1.0;
  for (int step = 0; step < 24 && hi / lo > 1.001; ++step) {
    double mid = std::sqrt(lo * hi);
    Outcome o = cl.run(mid);
    if (!o.valid || !(o.bound <= max_error)) {
      hi = mid;
      continue;
    }
    if (fewest.leader.empty() || o.triangles < fewest.triangles) fewest = o;
    if (o.triangles <= target) {
      best = std::move(o);
      hi = mid;
    } else {
      lo = mid;
    }
  }
  Result r;
  if (!best.leader.empty()) {
    r = cl.output(best);
  } else if (!fewest.leader.empty() && fewest.triangles < cl.input_triangles()) {
    r = cl.output(fewest);
    r.target_reached = false;
  } else {  // nothing within the error limit: the input, with its prior error
    r.mesh = mesh;
    r.input_triangles = mesh.triangle_count();
    r.vertex_error.assign(mesh.vertex_count(), 0.0f);
    for (size_t v = 0; v < prior_error.size() && v < mesh.vertex_count(); ++v)
      r.vertex_error[v] = prior_error[v];
    for (float e : r.vertex_error) r.error_bound = std::max(r.error_bound, double(e));
    r.target_reached = mesh.triangle_count() <= target;
  }
  return r;
}

}  // namespace lodstream::simplify
