// Bake's records on a real package (refined_elephant): consecutive groups of one level share a record
// (cmd_bake.cpp, join_groups), each group's input clusters whole in one record, never clusters of two levels.
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <tuple>

#include "baked.hpp"
#include "package/reader.hpp"

using namespace lodstream;

TEST(BakeRecords, ConsecutiveGroupsOfALevelShareARecordWhole) {
  auto reader = package::PackageReader::open(test::elephant_package());
  // A record is identified by its bytes' place; a group's input clusters by their parents (the clusters the
  // group made, the same list for each of its inputs).
  using Place = std::tuple<uint32_t, uint32_t>;
  std::map<Place, std::set<std::vector<uint32_t>>> groups_of;
  std::map<Place, std::set<uint32_t>> levels_of;
  std::map<Place, uint32_t> clusters_of;
  std::map<std::vector<uint32_t>, std::set<Place>> places_of;
  for (uint32_t id = 0; id < reader.node_count(); ++id) {
    const package::NodeRecord n = reader.node(id);
    if (n.parents.empty()) continue;  // a root
    const Place place{n.page, n.offset};
    groups_of[place].insert(n.parents);
    levels_of[place].insert(n.level);
    ++clusters_of[place];
    places_of[n.parents].insert(place);
  }
  size_t joined = 0;
  for (const auto& [place, groups] : groups_of) {
    EXPECT_EQ(levels_of[place].size(), 1u);
    EXPECT_LE(clusters_of[place], 31u);
    joined += groups.size() > 1;
  }
  for (const auto& [group, places] : places_of) EXPECT_EQ(places.size(), 1u);
  // Most records join several groups (one group's inputs are about 8 clusters of the 31 a record holds).
  EXPECT_GT(joined, groups_of.size() / 2) << joined << " of " << groups_of.size();
}
