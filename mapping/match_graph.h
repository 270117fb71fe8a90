#pragma once
// The match graph of a COLMAP database and its partition into leaves for mapping a venue in
// parts (`arview map --leaf-size`, mapping/leaf_mapping.h), as COLMAP's hierarchical mapper does:
// the images are the vertices, each verified pair an edge weighted by its inlier count; METIS cuts
// the graph where it is weakest (never by frame index) into leaves of at most `leaf_size` images,
// and each leaf then takes in the outside images most strongly tied to it, so that neighbouring
// leaves share images for the merge.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "mapping/colmap_model.h"

namespace arview::mapping {

struct GraphEdge {
  int a = 0, b = 0;  // vertex indices
  int weight = 0;    // inliers
};

struct MatchGraph {
  std::vector<std::string> names;  // vertex -> COLMAP's image name
  std::vector<GraphEdge> edges;    // each pair once
};

// The graph of a database's images and verified pairs (pairs with fewer than `min_inliers`
// inliers are left out). Throws MapError when the database cannot be read.
MatchGraph BuildMatchGraph(const DatabaseMatchGraph& database, int min_inliers = 15);

struct PartitionOptions {
  int leaf_size = 0;   // at most this many images in a leaf before the overlap (> 1)
  int overlap = 10;    // outside images added to each leaf, the most strongly tied first
  // A venue's rooms: each vertex's room (empty: none). Leaves are then cut within rooms, never
  // across one's walls: each room is partitioned on its own, and a room too small to map alone
  // (under 10 images) goes with the room it shares most inliers with.
  std::vector<int> room_of;
};

struct Leaf {
  std::vector<int> core;     // the vertices METIS put in this leaf (each vertex in one leaf's core)
  std::vector<int> overlap;  // the outside vertices added, strongest tie first
  std::vector<int> All() const;
};

struct Partition {
  std::vector<Leaf> leaves;
  long long cut_weight = 0;  // the inliers of the edges between different leaves' cores
};

// Recursive bisection with METIS (edge weights = inliers), within each room when rooms are
// given, until every leaf holds at most options.leaf_size vertices, each connected part of a subgraph bisected apart (a part of fewer
// than 10 vertices goes with the largest), then the overlap. A graph of at most leaf_size vertices is one leaf.
// Deterministic (METIS's seed is fixed). Throws MapError when METIS fails or the options are
// out of range.
Partition PartitionMatchGraph(const MatchGraph& graph, const PartitionOptions& options);

// The total weight of the edges between vertices of different groups (`group` per vertex).
long long CutWeight(const MatchGraph& graph, const std::vector<int>& group);

}  // namespace arview::mapping
