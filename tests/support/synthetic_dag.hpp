// A hand-made cluster DAG for the runtime tests: 16 leaf clusters on the x axis, leaf i covering the interval
// [i, i+1); group simplifications merge contiguous runs across the outputs of different groups (so nodes have
// several parents and groups mix simplification outputs), and every node covers a known interval of [0, 16):
// Ids: leaves 0-15, a0 a1 16 17, b 18 19, c 20 21, d0 22, e 23 24, f 25 26, g0 27, r0 r1 28 29.
//   level 1: {0-3} -> a0 [0,2) a1 [2,4); {4-7} -> b0, b1; {8-11} -> c0, c1; {12-15} -> d0 [12,16)
//   level 2: {a0, a1, b0} -> e0 [0,3) e1 [3,6); {b1, c0, c1} -> f0 [6,9) f1 [9,12); {d0} -> g0 [12,16)
//   level 3: {e0, e1, f0, f1, g0} -> r0 [0,8) r1 [8,16)   (the roots)
// Errors grow by level (0, 0.01, 0.03, 0.1 object units); spheres are shared per group and contain the
// children's. A cut is exactly one covering when its nodes' intervals partition [0, 16).
#pragma once

#include <algorithm>
#include <cmath>
#include <set>
#include <unordered_set>
#include <vector>

#include "package/index.hpp"
#include "schedule/cut.hpp"

namespace lodstream::test {

struct SyntheticDag {
  std::vector<package::NodeRecord> records;
  std::vector<std::pair<double, double>> intervals;  // per node
  std::vector<uint32_t> roots;

  uint32_t leaf(double x0, uint32_t triangles) {
    package::NodeRecord r;
    r.triangles = triangles;
    r.sphere = {{float(x0 + 0.5), 0.0f, 0.0f}, 0.5f};
    records.push_back(r);
    intervals.push_back({x0, x0 + 1});
    return uint32_t(records.size() - 1);
  }

  // Simplifies `children` into outputs covering the given intervals, each with `triangles`.
  std::vector<uint32_t> group(const std::vector<uint32_t>& children,
                              const std::vector<std::pair<double, double>>& outputs, uint32_t triangles,
                              float error) {
    Sphere s;
    glm::vec3 sum(0.0f);
    for (uint32_t c : children) sum += records[c].sphere.center;
    s.center = sum / float(children.size());
    for (uint32_t c : children)
      s.radius =
          std::max(s.radius, glm::length(records[c].sphere.center - s.center) + records[c].sphere.radius);
    s.radius *= 1.0001f;
    std::vector<uint32_t> ids;
    for (auto iv : outputs) {
      package::NodeRecord r;
      r.level = records[children[0]].level + 1;
      r.triangles = triangles;
      r.error = error;
      r.sphere = s;
      r.children = children;
      records.push_back(r);
      intervals.push_back(iv);
      ids.push_back(uint32_t(records.size() - 1));
    }
    for (uint32_t c : children) {
      records[c].parents = ids;
      records[c].parent_error = error;
      records[c].parent_sphere = s;
    }
    return ids;
  }

  static SyntheticDag make() {
    SyntheticDag d;
    std::vector<uint32_t> l;
    for (int i = 0; i < 16; ++i) l.push_back(d.leaf(i, 100));
    auto a = d.group({l[0], l[1], l[2], l[3]}, {{0, 2}, {2, 4}}, 100, 0.01f);
    auto b = d.group({l[4], l[5], l[6], l[7]}, {{4, 6}, {6, 8}}, 100, 0.01f);
    auto c = d.group({l[8], l[9], l[10], l[11]}, {{8, 10}, {10, 12}}, 100, 0.01f);
    auto dd = d.group({l[12], l[13], l[14], l[15]}, {{12, 16}}, 150, 0.01f);
    auto e = d.group({a[0], a[1], b[0]}, {{0, 3}, {3, 6}}, 80, 0.03f);
    auto f = d.group({b[1], c[0], c[1]}, {{6, 9}, {9, 12}}, 80, 0.03f);
    auto g = d.group({dd[0]}, {{12, 16}}, 70, 0.03f);
    d.roots = d.group({e[0], e[1], f[0], f[1], g[0]}, {{0, 8}, {8, 16}}, 100, 0.1f);
    return d;
  }

  // A scene with one representation (this DAG) and the given object transforms.
  package::PackageScene scene(const std::vector<glm::mat4>& transforms) const {
    package::PackageScene s;
    package::Representation rep;
    rep.bounds.add(glm::vec3(-0.5f, -0.5f, -0.5f));
    rep.bounds.add(glm::vec3(16.5f, 0.5f, 0.5f));
    rep.levels = 4;
    rep.roots = roots;
    s.representations.push_back(rep);
    for (const auto& t : transforms) s.objects.push_back({"o", t, 0});
    for (const package::NodeRecord& r : records)  // the finest level: what it was "baked" from
      if (r.children.empty()) s.input_triangles += r.triangles * transforms.size();
    return s;
  }
};

// NodeSource over the DAG with a set of unavailable and unknown nodes.
struct TestNodes : schedule::NodeSource {
  const SyntheticDag& dag;
  std::unordered_set<uint32_t> unavailable, unknown;
  explicit TestNodes(const SyntheticDag& d) : dag(d) {}
  const package::NodeRecord* record(uint32_t id) const override {
    return unknown.count(id) ? nullptr : &dag.records.at(id);
  }
  bool available(uint32_t id) const override { return !unavailable.count(id) && !unknown.count(id); }
};

}  // namespace lodstream::test
