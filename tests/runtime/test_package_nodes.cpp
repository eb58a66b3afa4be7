#include <gtest/gtest.h>

#include "package/reader.hpp"
#include "package/writer.hpp"
#include "runtime/package_nodes.hpp"
#include "support/run.hpp"
#include "support/synthetic_dag.hpp"

using namespace lodstream;
using namespace lodstream::runtime;

// A pull loop on a real package file: select the cut from what has arrived, fetch what it reports missing
// (index pages for unknown records, data pages for unavailable nodes), repeat. Every intermediate cut is one
// covering of the surface drawn from arrived pages only, and the loop converges to the cut of the fully
// available DAG.
TEST(PackageNodes, PullLoopConvergesToTheIdealCut) {
  test::SyntheticDag dag = test::SyntheticDag::make();
  const auto file = test::temp_dir() / "dag.lods";
  package::WriterOptions options;
  options.page_bytes = 2048;
  options.nodes_per_index_page = 8;
  {
    package::PackageWriter writer(file, options);
    for (uint32_t i = 0; i < dag.records.size(); ++i) {
      dag.records[i].encoding = package::NodeEncoding::raw;
      writer.add_node(i, std::vector<uint8_t>(700, uint8_t(i)));
      writer.end_group();
    }
    package::PackageScene scene = dag.scene({glm::mat4(1.0f)});
    scene.materials = {package::PackageMaterial{}};
    writer.finish(scene, dag.records, 4);  // the roots (28, 29) are in an index page, not the root index
  }
  package::PackageReader reader = package::PackageReader::open(file);
  ASSERT_FALSE(reader.has_node(28));
  PageCache cache(1u << 20);
  PackageNodes nodes(reader, cache);
  const auto& scene = reader.scene();
  Camera c;
  c.eye = {-1.0f, 0.5f, 1.0f};
  c.target = {8.0f, 0.0f, 0.0f};
  const View view = View::of(c);
  const double tau = 0.5;

  test::TestNodes everything(dag);
  const Cut ideal = select_cut(scene, everything, view, {tau});
  Cut cut;
  int rounds = 0;
  for (; rounds < 20; ++rounds) {
    cut = select_cut(scene, nodes, view, {tau});
    std::vector<std::pair<double, double>> parts;
    for (const auto& d : cut.drawn) {
      EXPECT_TRUE(cache.contains(reader.header().content_hash, reader.node(d.node).page));
      parts.push_back(dag.intervals[d.node]);
    }
    std::sort(parts.begin(), parts.end());
    for (size_t i = 1; i < parts.size(); ++i) EXPECT_EQ(parts[i].first, parts[i - 1].second);
    if (cut.converged()) break;
    for (const auto& m : cut.missing) {
      if (!m.record_known)
        reader.node(m.node);  // loads its index page
      else
        cache.insert(reader.header().content_hash, reader.node(m.node).page,
                     reader.read_page(reader.node(m.node).page));
    }
  }
  EXPECT_GE(rounds, 3);  // index page, roots, then levels
  ASSERT_TRUE(cut.converged());
  ASSERT_EQ(cut.drawn.size(), ideal.drawn.size());
  for (size_t i = 0; i < cut.drawn.size(); ++i) EXPECT_EQ(cut.drawn[i].node, ideal.drawn[i].node);
}
