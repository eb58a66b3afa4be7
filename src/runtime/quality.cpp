#include "runtime/quality.hpp"

#include <algorithm>
#include <cmath>

namespace lodstream::runtime {

FrameQuality frame_quality(const package::PackageScene& scene, const NodeSource& nodes, const Cut& cut,
                           const View& view, double tau) {
  const size_t n = scene.objects.size();
  std::vector<double> weight(n, 0.0), accuracy(n, 0.0), error(n, 0.0);
  std::vector<size_t> count(n, 0);
  std::vector<double> plain(n, 0.0);  // unweighted sum, for an object whose nodes all have zero area
  auto add = [&](uint32_t object, double a, const DrawnNode& d) {
    const double alpha = d.error_px > 0.0 ? std::min(1.0, tau / d.error_px) : 1.0;
    weight[object] += a;
    accuracy[object] += a * alpha;
    plain[object] += alpha;
    ++count[object];
    error[object] = std::max(error[object], d.error_px);
  };
  for (const DrawnNode& d : cut.drawn) {
    if (d.refined) continue;  // a progressive step below the last drawn one (cut.hpp)
    const package::NodeRecord& r = *nodes.record(d.node);
    if (d.object == package::kNone) {  // an HLOD proxy: each object it stands for is drawn at its error
      for (uint32_t o : r.objects)
        if (o < n && cut.objects[o] != ObjectState::culled)
          add(o, projected_area(object_sphere(scene, o), view), d);
      continue;
    }
    const package::ObjectRecord& o = scene.objects[d.object];
    add(d.object, projected_area(to_world(r.sphere, o.transform, max_scale(o.transform)), view), d);
  }
  FrameQuality q;
  double covered = 0.0, benefit = 0.0;
  size_t drawn_objects = 0;
  for (uint32_t i = 0; i < n; ++i) {
    if (cut.objects[i] == ObjectState::culled) continue;
    ++q.visible_objects;
    const double a = projected_area(object_sphere(scene, i), view);
    double alpha = 0.0;
    if (count[i] > 0) {
      alpha = weight[i] > 0.0 ? accuracy[i] / weight[i] : plain[i] / double(count[i]);
      q.pixel_error_max = std::max(q.pixel_error_max, error[i]);
      q.pixel_error_mean += error[i];
      ++drawn_objects;
    }
    covered += a;
    benefit += a * alpha;
  }
  if (drawn_objects > 0) q.pixel_error_mean /= double(drawn_objects);
  q.benefit_ratio = covered > 0.0 ? benefit / covered : 1.0;
  return q;
}

}  // namespace lodstream::runtime
