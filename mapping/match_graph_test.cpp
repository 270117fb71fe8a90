// The match graph and its partition into leaves (mapping/match_graph.h): synthetic graphs whose
// best cut is known, and templeRing's database (the shared map of test_temple_map.h).

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "mapping/match_graph.h"
#include "mapping/test_temple_map.h"
#include "tests/support/test_data.h"

namespace arview::mapping {
namespace {

// Two cliques of `size` vertices each with strong edges inside, joined by one weak edge; the
// cliques' vertices interleave by index (even: one clique, odd: the other), so that a split by
// index cuts every strong edge.
MatchGraph InterleavedCliques(int size) {
  MatchGraph g;
  for (int v = 0; v < 2 * size; ++v) g.names.push_back("frame_" + std::to_string(v) + ".png");
  for (int a = 0; a < 2 * size; ++a) {
    for (int b = a + 2; b < 2 * size; b += 2) g.edges.push_back({a, b, 200});
  }
  g.edges.push_back({0, 1, 20});
  return g;
}

void ExpectEveryVertexInOneCore(const Partition& p, int vertices) {
  std::vector<int> seen(vertices, 0);
  for (const auto& leaf : p.leaves) {
    for (const int v : leaf.core) ++seen[v];
  }
  for (int v = 0; v < vertices; ++v) EXPECT_EQ(seen[v], 1) << "vertex " << v;
}

TEST(MatchGraph, CutsBetweenTheCliquesNotByIndex) {
  const MatchGraph g = InterleavedCliques(10);
  const Partition p = PartitionMatchGraph(g, {10, 0, {}});
  ASSERT_EQ(p.leaves.size(), 2u);
  ExpectEveryVertexInOneCore(p, 20);
  for (const auto& leaf : p.leaves) {
    ASSERT_EQ(leaf.core.size(), 10u);
    const int parity = leaf.core.front() % 2;
    for (const int v : leaf.core) EXPECT_EQ(v % 2, parity) << "vertex " << v << " in the other clique's leaf";
  }
  EXPECT_EQ(p.cut_weight, 20);
}

TEST(MatchGraph, SplitsUntilEveryLeafFits) {
  const MatchGraph g = InterleavedCliques(10);
  const Partition p = PartitionMatchGraph(g, {4, 0, {}});
  EXPECT_GE(p.leaves.size(), 5u);
  ExpectEveryVertexInOneCore(p, 20);
  for (const auto& leaf : p.leaves) EXPECT_LE(leaf.core.size(), 4u);
}

TEST(MatchGraph, OverlapTakesTheMostStronglyTiedOutsideImages) {
  MatchGraph g = InterleavedCliques(6);
  // Vertex 1 (odd clique) tied to the even clique more strongly than vertex 3.
  g.edges.push_back({1, 2, 150});
  g.edges.push_back({3, 4, 60});
  const Partition p = PartitionMatchGraph(g, {6, 2, {}});
  ASSERT_EQ(p.leaves.size(), 2u);
  const Leaf& even = p.leaves[0].core.front() % 2 == 0 ? p.leaves[0] : p.leaves[1];
  EXPECT_EQ(even.overlap, (std::vector<int>{1, 3}));
  const std::vector<int> all = even.All();
  EXPECT_EQ(all.size(), 8u);
}

TEST(MatchGraph, ASmallGraphIsOneLeafWithoutOverlap) {
  const Partition p = PartitionMatchGraph(InterleavedCliques(3), {6, 5, {}});
  ASSERT_EQ(p.leaves.size(), 1u);
  EXPECT_EQ(p.leaves[0].core.size(), 6u);
  EXPECT_TRUE(p.leaves[0].overlap.empty());
  EXPECT_EQ(p.cut_weight, 0);
}

TEST(MatchGraph, AGraphWithoutEdgesIsStillSplit) {
  MatchGraph g;
  for (int v = 0; v < 9; ++v) g.names.push_back(std::to_string(v));
  const Partition p = PartitionMatchGraph(g, {3, 1, {}});
  ExpectEveryVertexInOneCore(p, 9);
  for (const auto& leaf : p.leaves) {
    EXPECT_LE(leaf.core.size(), 3u);
    EXPECT_TRUE(leaf.overlap.empty()) << "no edge, no overlap";
  }
}

// Rooms recorded apart that never matched each other: chains of frames, each matched with its
// next two.
MatchGraph UnmatchedChains(const std::vector<int>& sizes) {
  MatchGraph g;
  int first = 0;
  for (const int size : sizes) {
    for (int v = first; v < first + size; ++v) {
      g.names.push_back("frame_" + std::to_string(v) + ".png");
      for (int next = v + 1; next <= v + 2 && next < first + size; ++next) g.edges.push_back({v, next, 200});
    }
    first += size;
  }
  return g;
}

TEST(MatchGraph, ALeafNeverHoldsFramesThatShareNoMatch) {
  // Balanced halves of 100 would put 20 frames of the 40-chain with each 30-chain.
  const Partition p = PartitionMatchGraph(UnmatchedChains({30, 30, 40}), {50, 0, {}});
  ASSERT_EQ(p.leaves.size(), 3u);
  ExpectEveryVertexInOneCore(p, 100);
  std::multiset<std::size_t> sizes;
  for (const auto& leaf : p.leaves) {
    sizes.insert(leaf.core.size());
    const auto [low, high] = std::minmax_element(leaf.core.begin(), leaf.core.end());
    EXPECT_EQ(static_cast<std::size_t>(*high - *low + 1), leaf.core.size()) << "a leaf of two chains";
  }
  EXPECT_EQ(sizes, (std::multiset<std::size_t>{30, 30, 40}));
  EXPECT_EQ(p.cut_weight, 0);
}

TEST(MatchGraph, APartTooSmallToMapAloneGoesWithTheLargest) {
  // 4 frames that matched nothing else: alone, COLMAP's mapper would keep no model of them.
  const Partition p = PartitionMatchGraph(UnmatchedChains({30, 4}), {40, 0, {}});
  ASSERT_EQ(p.leaves.size(), 1u);
  EXPECT_EQ(p.leaves[0].core.size(), 34u);
}

// One chain of 60 frames walked through three rooms (frames 0-19, 20-49, 50-59) and matched
// across the doors as within rooms: METIS alone would cut two balanced leaves of 30, each across a
// door; with the rooms given each leaf stays within a room (the 30-frame room split no further:
// it fits), and a room of 5 frames, too small to map alone, goes with the room it matched most.
TEST(MatchGraph, WithRoomsGivenLeavesAreCutWithinRooms) {
  const MatchGraph g = UnmatchedChains({60});
  std::vector<int> room_of(60);
  for (int v = 0; v < 60; ++v) room_of[v] = v < 20 ? 0 : v < 50 ? 1 : 2;
  const Partition p = PartitionMatchGraph(g, {30, 2, room_of});
  ExpectEveryVertexInOneCore(p, 60);
  std::multiset<std::size_t> sizes;
  for (const auto& leaf : p.leaves) {
    sizes.insert(leaf.core.size());
    for (const int v : leaf.core) EXPECT_EQ(room_of[v], room_of[leaf.core.front()]) << "vertex " << v << " crosses a room";
    EXPECT_EQ(leaf.overlap.size(), 2u) << "the overlap still comes from the next room";
  }
  EXPECT_EQ(sizes, (std::multiset<std::size_t>{20, 30, 10}));

  // The walk ends 5 frames into the third room (frames 50-54): they go with the second room's.
  const MatchGraph shorter = UnmatchedChains({55});
  const std::vector<int> short_rooms(room_of.begin(), room_of.begin() + 55);
  const Partition q = PartitionMatchGraph(shorter, {40, 0, short_rooms});
  ExpectEveryVertexInOneCore(q, 55);
  std::multiset<std::size_t> q_sizes;
  for (const auto& leaf : q.leaves) {
    q_sizes.insert(leaf.core.size());
    const bool first_room = room_of[leaf.core.front()] == 0;
    for (const int v : leaf.core) EXPECT_EQ(room_of[v] == 0, first_room) << "vertex " << v;
  }
  EXPECT_EQ(q_sizes, (std::multiset<std::size_t>{20, 35})) << "frames 50-54 join frames 20-49";
  EXPECT_THROW(PartitionMatchGraph(g, {30, 0, {0, 1}}), map::MapError) << "two rooms given for 60 frames";
}

TEST(MatchGraph, RefusesALeafOfOneImage) {
  try {
    PartitionMatchGraph(InterleavedCliques(3), {1, 0, {}});
    FAIL() << "a leaf size of 1 was accepted";
  } catch (const map::MapError& e) {
    EXPECT_NE(std::string(e.what()).find("leaf size 1"), std::string::npos) << e.what();
  }
}

TEST(MatchGraph, WeakPairsAreLeftOut) {
  DatabaseMatchGraph db;
  db.images = {{1, "a.png"}, {2, "b.png"}, {3, "c.png"}};
  db.pairs = {{1, 2, 100}, {2, 3, 14}, {1, 9, 300}};  // image 9 is not listed
  const MatchGraph g = BuildMatchGraph(db, 15);
  ASSERT_EQ(g.names, (std::vector<std::string>{"a.png", "b.png", "c.png"}));
  ASSERT_EQ(g.edges.size(), 1u);
  EXPECT_EQ(g.edges[0].a, 0);
  EXPECT_EQ(g.edges[0].b, 1);
  EXPECT_EQ(g.edges[0].weight, 100);
}

// templeRing's 24 even frames, matched exhaustively: leaves of at most 8 images, each with
// overlap into the others; METIS's cut no heavier than cutting the ring by frame index.
TEST(TempleMatchGraph, LeavesOfTheRingCutWhereTheMatchesAreFewest) {
  const auto source = testing::SharedData("templeRing");
  ARVIEW_REQUIRE_DATA_PATH(source, "../shared/data");
  recordings::Recording recording;
  testing::BuildSharedTempleMap(source, &recording);
  const MatchGraph g = BuildMatchGraph(ReadMatchGraph(testing::TempleMapRoot() / "map" / "database.db"));
  ASSERT_EQ(g.names.size(), 24u);
  ASSERT_GT(g.edges.size(), 24u);
  const Partition p = PartitionMatchGraph(g, {8, 4, {}});
  ASSERT_EQ(p.leaves.size(), 4u);  // 24 → 12 + 12 → four of 6
  ExpectEveryVertexInOneCore(p, 24);
  std::vector<int> by_index(24);
  for (int v = 0; v < 24; ++v) by_index[v] = v / 6;  // the database lists the frames in order
  EXPECT_LE(p.cut_weight, CutWeight(g, by_index));
  for (const auto& leaf : p.leaves) {
    EXPECT_LE(leaf.core.size(), 8u);
    EXPECT_GE(leaf.overlap.size(), 1u);  // fewer than 4 where fewer outside images match into it
    EXPECT_LE(leaf.overlap.size(), 4u);
    const std::set<int> core(leaf.core.begin(), leaf.core.end());
    for (const int v : leaf.overlap) {
      EXPECT_EQ(core.count(v), 0u);
      const bool tied = std::any_of(g.edges.begin(), g.edges.end(), [&](const GraphEdge& e) {
        return (e.a == v && core.count(e.b)) || (e.b == v && core.count(e.a));
      });
      EXPECT_TRUE(tied) << g.names[v] << " overlaps a leaf it has no match into";
    }
  }
}

}  // namespace
}  // namespace arview::mapping
