#include "mapping/match_graph.h"

#include <metis.h>

#include <algorithm>
#include <numeric>
#include <unordered_map>

#include "map/map.h"

namespace arview::mapping {

namespace {

// The subgraph on `vertices` in METIS's compressed form (local indices).
struct CsrGraph {
  std::vector<idx_t> xadj{0}, adjncy, adjwgt;
};

CsrGraph InducedSubgraph(const std::vector<std::vector<std::pair<int, int>>>& adjacency, const std::vector<int>& vertices) {
  std::unordered_map<int, idx_t> local;
  for (std::size_t i = 0; i < vertices.size(); ++i) local[vertices[i]] = static_cast<idx_t>(i);
  CsrGraph csr;
  for (const int v : vertices) {
    for (const auto& [u, weight] : adjacency[v]) {
      const auto it = local.find(u);
      if (it == local.end()) continue;
      csr.adjncy.push_back(it->second);
      csr.adjwgt.push_back(weight);
    }
    csr.xadj.push_back(static_cast<idx_t>(csr.adjncy.size()));
  }
  return csr;
}

// `vertices` cut in two halves of (nearly) equal size where the edges are weakest.
std::pair<std::vector<int>, std::vector<int>> Bisect(const std::vector<std::vector<std::pair<int, int>>>& adjacency,
                                                     const std::vector<int>& vertices) {
  CsrGraph csr = InducedSubgraph(adjacency, vertices);
  idx_t n = static_cast<idx_t>(vertices.size()), constraints = 1, parts = 2, cut = 0;
  std::vector<idx_t> part(vertices.size(), 0);
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = 1;
  options[METIS_OPTION_NUMBERING] = 0;
  const int rc = METIS_PartGraphRecursive(&n, &constraints, csr.xadj.data(), csr.adjncy.data(), nullptr, nullptr,
                                          csr.adjwgt.data(), &parts, nullptr, nullptr, options, &cut, part.data());
  if (rc != METIS_OK) {
    throw map::MapError("METIS could not partition the match graph of " + std::to_string(vertices.size()) +
                        " images (METIS error " + std::to_string(rc) + ")");
  }
  std::pair<std::vector<int>, std::vector<int>> halves;
  for (std::size_t i = 0; i < vertices.size(); ++i) (part[i] == 0 ? halves.first : halves.second).push_back(vertices[i]);
  // METIS may leave a half empty on a graph without edges: split it in the middle then.
  if (halves.first.empty() || halves.second.empty()) {
    const auto middle = vertices.begin() + static_cast<std::ptrdiff_t>(vertices.size() / 2);
    halves = {std::vector<int>(vertices.begin(), middle), std::vector<int>(middle, vertices.end())};
  }
  return halves;
}

// A part of fewer frames than this is mapped with the largest part of its subgraph, not alone:
// COLMAP's mapper keeps no model of fewer than 10 images (--Mapper.min_model_size), and a leaf
// without a model fails the whole map.
constexpr int kLeastFramesOfALeaf = 10;

// The connected parts of the subgraph on `vertices`, largest first (ties: the lowest vertex).
std::vector<std::vector<int>> ConnectedParts(const std::vector<std::vector<std::pair<int, int>>>& adjacency,
                                             const std::vector<int>& vertices) {
  std::unordered_map<int, int> part_of;  // vertex -> part, -1 not yet reached
  for (const int v : vertices) part_of[v] = -1;
  std::vector<std::vector<int>> parts;
  for (const int start : vertices) {
    if (part_of[start] >= 0) continue;
    const int part = static_cast<int>(parts.size());
    parts.push_back({start});
    part_of[start] = part;
    for (std::size_t next = 0; next < parts[part].size(); ++next) {
      for (const auto& [u, weight] : adjacency[parts[part][next]]) {
        const auto it = part_of.find(u);
        if (it == part_of.end() || it->second >= 0) continue;
        it->second = part;
        parts[part].push_back(u);
      }
    }
  }
  std::stable_sort(parts.begin(), parts.end(), [](const auto& a, const auto& b) { return a.size() > b.size(); });
  return parts;
}

void SplitUntilSmall(const std::vector<std::vector<std::pair<int, int>>>& adjacency, const std::vector<int>& vertices,
                     int leaf_size, std::vector<Leaf>* leaves);

void BisectUntilSmall(const std::vector<std::vector<std::pair<int, int>>>& adjacency, const std::vector<int>& vertices,
                      int leaf_size, std::vector<Leaf>* leaves) {
  if (static_cast<int>(vertices.size()) <= leaf_size) {
    leaves->push_back({vertices, {}});
    return;
  }
  const auto [first, second] = Bisect(adjacency, vertices);
  SplitUntilSmall(adjacency, first, leaf_size, leaves);
  SplitUntilSmall(adjacency, second, leaf_size, leaves);
}

// Each connected part of `vertices` bisected apart. METIS's halves are of (nearly) equal size,
// and to balance them it may put frames that share no match in one half (the rendered venue's
// every-frame walk in leaves of 200: a leaf of 102 frames of one room and 56 of another, of which
// the leaf's mapper registered the 102 and the merge then failed); a leaf of such a half maps as
// one of its parts only.
void SplitUntilSmall(const std::vector<std::vector<std::pair<int, int>>>& adjacency, const std::vector<int>& vertices,
                     int leaf_size, std::vector<Leaf>* leaves) {
  std::vector<std::vector<int>> parts = ConnectedParts(adjacency, vertices);
  const std::size_t least = static_cast<std::size_t>(std::min(kLeastFramesOfALeaf, leaf_size));
  std::vector<int> largest = parts.front();
  for (std::size_t i = 1; i < parts.size(); ++i)
    if (parts[i].size() < least) largest.insert(largest.end(), parts[i].begin(), parts[i].end());
  BisectUntilSmall(adjacency, largest, leaf_size, leaves);
  for (std::size_t i = 1; i < parts.size(); ++i)
    if (parts[i].size() >= least) BisectUntilSmall(adjacency, parts[i], leaf_size, leaves);
}

// The `count` outside vertices with the strongest single edge into the leaf (as COLMAP's scene
// clustering picks its overlapping images), strongest first; ties by vertex.
std::vector<int> StrongestOutside(const std::vector<std::vector<std::pair<int, int>>>& adjacency,
                                  const std::vector<int>& core, int count) {
  std::vector<char> inside(adjacency.size(), 0);
  for (const int v : core) inside[v] = 1;
  std::unordered_map<int, int> strongest;
  for (const int v : core) {
    for (const auto& [u, weight] : adjacency[v]) {
      if (!inside[u]) strongest[u] = std::max(strongest[u], weight);
    }
  }
  std::vector<std::pair<int, int>> ranked(strongest.begin(), strongest.end());
  std::sort(ranked.begin(), ranked.end(),
            [](const auto& x, const auto& y) { return x.second != y.second ? x.second > y.second : x.first < y.first; });
  std::vector<int> chosen;
  for (std::size_t i = 0; i < ranked.size() && static_cast<int>(i) < count; ++i) chosen.push_back(ranked[i].first);
  return chosen;
}

}  // namespace

std::vector<int> Leaf::All() const {
  std::vector<int> all = core;
  all.insert(all.end(), overlap.begin(), overlap.end());
  return all;
}

MatchGraph BuildMatchGraph(const DatabaseMatchGraph& database, int min_inliers) {
  MatchGraph graph;
  std::unordered_map<std::uint32_t, int> vertex_of_image;
  for (const auto& [id, name] : database.images) {
    vertex_of_image[id] = static_cast<int>(graph.names.size());
    graph.names.push_back(name);
  }
  for (const auto& pair : database.pairs) {
    if (pair.inliers < min_inliers || pair.image_a == pair.image_b) continue;
    const auto a = vertex_of_image.find(pair.image_a), b = vertex_of_image.find(pair.image_b);
    if (a == vertex_of_image.end() || b == vertex_of_image.end()) continue;  // a pair of an image no longer listed
    graph.edges.push_back({a->second, b->second, pair.inliers});
  }
  return graph;
}

namespace {

// The vertices of each room (room_of per vertex), a room of fewer than kLeastFramesOfALeaf (or
// leaf_size) vertices put into the room it shares most edge weight with, smallest rooms first.
std::vector<std::vector<int>> RoomsLargeEnough(const std::vector<std::vector<std::pair<int, int>>>& adjacency,
                                               const std::vector<int>& room_of, int leaf_size) {
  std::vector<int> room = room_of;
  const int rooms = room.empty() ? 0 : *std::max_element(room.begin(), room.end()) + 1;
  const std::size_t least = static_cast<std::size_t>(std::min(kLeastFramesOfALeaf, leaf_size));
  const auto members = [&] {
    std::vector<std::vector<int>> m(static_cast<std::size_t>(std::max(rooms, 0)));
    for (std::size_t v = 0; v < room.size(); ++v)
      if (room[v] >= 0) m[static_cast<std::size_t>(room[v])].push_back(static_cast<int>(v));
    return m;
  };
  for (bool moved = true; moved;) {
    moved = false;
    std::vector<std::vector<int>> m = members();
    std::size_t smallest = m.size();
    for (std::size_t r = 0; r < m.size(); ++r)
      if (!m[r].empty() && m[r].size() < least && (smallest == m.size() || m[r].size() < m[smallest].size())) smallest = r;
    if (smallest == m.size()) break;
    std::vector<long long> tie(m.size(), 0);
    for (const int v : m[smallest])
      for (const auto& [u, weight] : adjacency[v])
        if (room[u] >= 0 && room[u] != static_cast<int>(smallest)) tie[static_cast<std::size_t>(room[u])] += weight;
    const auto strongest = std::max_element(tie.begin(), tie.end());
    if (*strongest == 0) break;  // tied to no other room: it stays a part of its own
    for (const int v : m[smallest]) room[v] = static_cast<int>(strongest - tie.begin());
    moved = true;
  }
  std::vector<std::vector<int>> grouped;
  for (std::vector<int>& r : members())
    if (!r.empty()) grouped.push_back(std::move(r));
  std::vector<int> outside;  // vertices in no room: a part of their own
  for (std::size_t v = 0; v < room.size(); ++v)
    if (room[v] < 0) outside.push_back(static_cast<int>(v));
  if (!outside.empty()) grouped.push_back(std::move(outside));
  return grouped;
}

}  // namespace

Partition PartitionMatchGraph(const MatchGraph& graph, const PartitionOptions& options) {
  if (options.leaf_size < 2) throw map::MapError("a leaf must hold at least 2 images (leaf size " + std::to_string(options.leaf_size) + ")");
  if (options.overlap < 0) throw map::MapError("the leaves' overlap cannot be negative (" + std::to_string(options.overlap) + ")");
  std::vector<std::vector<std::pair<int, int>>> adjacency(graph.names.size());
  for (const auto& e : graph.edges) {
    adjacency[e.a].emplace_back(e.b, e.weight);
    adjacency[e.b].emplace_back(e.a, e.weight);
  }
  std::vector<int> all(graph.names.size());
  std::iota(all.begin(), all.end(), 0);
  Partition partition;
  if (options.room_of.empty()) {
    SplitUntilSmall(adjacency, all, options.leaf_size, &partition.leaves);
  } else {
    if (options.room_of.size() != graph.names.size())
      throw map::MapError("the leaves' rooms: " + std::to_string(options.room_of.size()) + " given for " +
                          std::to_string(graph.names.size()) + " images");
    for (const std::vector<int>& room : RoomsLargeEnough(adjacency, options.room_of, options.leaf_size))
      SplitUntilSmall(adjacency, room, options.leaf_size, &partition.leaves);
  }
  std::vector<int> group(graph.names.size(), 0);
  for (std::size_t l = 0; l < partition.leaves.size(); ++l) {
    for (const int v : partition.leaves[l].core) group[v] = static_cast<int>(l);
  }
  partition.cut_weight = CutWeight(graph, group);
  if (partition.leaves.size() > 1) {
    for (auto& leaf : partition.leaves) leaf.overlap = StrongestOutside(adjacency, leaf.core, options.overlap);
  }
  return partition;
}

long long CutWeight(const MatchGraph& graph, const std::vector<int>& group) {
  long long cut = 0;
  for (const auto& e : graph.edges) {
    if (group[e.a] != group[e.b]) cut += e.weight;
  }
  return cut;
}

}  // namespace arview::mapping
