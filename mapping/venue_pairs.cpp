#include "mapping/venue_pairs.h"

#include <algorithm>
#include <set>
#include <sstream>

#include "map/descriptor_index.h"
#include "map/map.h"

namespace arview::mapping {

void CrossRoomOptions::Check(const OptionNames& names) const {
  RequireOption(neighbours >= 0, names("neighbours"), "0 (the rooms as one sequence) or more", neighbours);
  RequireOption(descriptors_per_frame >= 2, names("descriptors_per_frame"), "at least 2", descriptors_per_frame);
  RequireOption(min_votes >= 1, names("min_votes"), "at least 1", min_votes);
  RequireOption(max_ratio > 0 && max_ratio <= 1, names("max_ratio"), "in (0, 1]", max_ratio);
}

std::string VenuePairs::Describe(const std::vector<std::string>& room_names) const {
  std::ostringstream out;
  const int total_across = static_cast<int>(pairs.size()) - within;
  out << within << " pairs within rooms, " << total_across << " across";
  const auto name = [&](std::size_t r) { return r < room_names.size() ? room_names[r] : "room " + std::to_string(r); };
  std::string sep = ": ";
  std::vector<bool> joined(across.size(), false);
  for (std::size_t a = 0; a < across.size(); ++a)
    for (std::size_t b = a + 1; b < across[a].size(); ++b) {
      if (across[a][b] == 0) continue;
      out << sep << name(a) << " and " << name(b) << " " << across[a][b];
      sep = ", ";
      joined[a] = joined[b] = true;
    }
  for (std::size_t r = 0; r < joined.size(); ++r)
    if (!joined[r] && across.size() > 1)
      out << "; " << name(r) << " shares no frame with the others: it will be mapped apart, or not at all";
  return out.str();
}

namespace {

// `count` rows of `descriptors` taken evenly (all of them when it has no more).
cv::Mat EvenRows(const cv::Mat& descriptors, int count) {
  if (descriptors.rows <= count) return descriptors;
  cv::Mat sample(count, descriptors.cols, descriptors.type());
  for (int k = 0; k < count; ++k)
    descriptors.row(static_cast<int>(static_cast<long long>(k) * descriptors.rows / count)).copyTo(sample.row(k));
  return sample;
}

// One room's sampled descriptors in one index, each row's image beside it.
struct RoomIndex {
  cv::Mat rows;
  std::vector<std::uint32_t> image_of_row;
  map::DescriptorIndex index;
};

RoomIndex IndexRoom(const std::vector<int>& images, const std::vector<cv::Mat>& samples) {
  RoomIndex room;
  for (const int i : images) {
    const cv::Mat& s = samples[static_cast<std::size_t>(i)];
    if (s.empty()) continue;
    room.rows.push_back(s);
    room.image_of_row.insert(room.image_of_row.end(), static_cast<std::size_t>(s.rows), static_cast<std::uint32_t>(i));
  }
  if (!room.rows.empty()) room.index = map::DescriptorIndex(room.rows);
  return room;
}

// Image `i`'s frames of other rooms with at least min_votes votes, most first, at most `neighbours`.
std::vector<int> NearestOtherFrames(int i, const std::vector<int>& room_of, const std::vector<cv::Mat>& samples,
                                    const std::vector<RoomIndex>& rooms, const CrossRoomOptions& options) {
  const cv::Mat& query = samples[static_cast<std::size_t>(i)];
  std::vector<std::pair<int, int>> votes;  // (votes, image)
  if (query.empty()) return {};
  for (std::size_t r = 0; r < rooms.size(); ++r) {
    if (static_cast<int>(r) == room_of[static_cast<std::size_t>(i)] || rooms[r].rows.empty()) continue;
    const std::vector<int> count = map::NearestNeighbourVotes(rooms[r].index, rooms[r].image_of_row, room_of.size(), query,
                                                              options.max_ratio);
    for (std::size_t j = 0; j < count.size(); ++j)
      if (count[j] >= options.min_votes) votes.emplace_back(count[j], static_cast<int>(j));
  }
  std::stable_sort(votes.begin(), votes.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<int> nearest;
  for (std::size_t k = 0; k < votes.size() && static_cast<int>(k) < options.neighbours; ++k) nearest.push_back(votes[k].second);
  return nearest;
}

}  // namespace

VenuePairs PairVenueFrames(const std::vector<int>& room_of, const std::vector<cv::Mat>& descriptors,
                           const std::function<std::vector<ImagePair>(int images)>& within,
                           const CrossRoomOptions& options, const std::function<void(int, int)>& progress,
                           const CancellationToken& cancel) {
  options.Check();
  if (room_of.size() != descriptors.size())
    throw map::MapError("venue pairs: " + std::to_string(room_of.size()) + " rooms given for " +
                        std::to_string(descriptors.size()) + " images");
  int rooms = 0;
  for (const int r : room_of) {
    if (r < 0) throw map::MapError("venue pairs: an image in no room");
    rooms = std::max(rooms, r + 1);
  }
  std::vector<std::vector<int>> members(static_cast<std::size_t>(rooms));
  for (std::size_t i = 0; i < room_of.size(); ++i) members[static_cast<std::size_t>(room_of[i])].push_back(static_cast<int>(i));

  VenuePairs out;
  out.across.assign(static_cast<std::size_t>(rooms), std::vector<int>(static_cast<std::size_t>(rooms), 0));
  std::set<std::pair<int, int>> seen;
  for (const std::vector<int>& images : members)
    for (const ImagePair& p : within(static_cast<int>(images.size()))) {
      const int a = images.at(static_cast<std::size_t>(p.first)), b = images.at(static_cast<std::size_t>(p.second));
      if (seen.emplace(std::min(a, b), std::max(a, b)).second) out.pairs.push_back({std::min(a, b), std::max(a, b)});
    }
  out.within = static_cast<int>(out.pairs.size());
  if (options.neighbours == 0 || rooms < 2) return out;

  std::vector<cv::Mat> samples(descriptors.size());
  for (std::size_t i = 0; i < descriptors.size(); ++i) samples[i] = EvenRows(descriptors[i], options.descriptors_per_frame);
  std::vector<RoomIndex> indices(static_cast<std::size_t>(rooms));
  ForEachInParallel(
      indices.size(), Workers(options.threads, indices.size()),
      [&](std::size_t r) { indices[r] = IndexRoom(members[r], samples); }, {}, cancel,
      "stopped indexing the rooms' descriptors");
  std::vector<std::vector<int>> nearest(descriptors.size());
  ForEachInParallel(
      descriptors.size(), Workers(options.threads, descriptors.size()),
      [&](std::size_t i) { nearest[i] = NearestOtherFrames(static_cast<int>(i), room_of, samples, indices, options); },
      progress, cancel, "stopped pairing frames across rooms");

  std::vector<ImagePair> across;
  for (std::size_t i = 0; i < nearest.size(); ++i)
    for (const int j : nearest[i]) {
      const int a = std::min(static_cast<int>(i), j), b = std::max(static_cast<int>(i), j);
      if (!seen.emplace(a, b).second) continue;
      across.push_back({a, b});
      const int ra = room_of[static_cast<std::size_t>(a)], rb = room_of[static_cast<std::size_t>(b)];
      ++out.across[static_cast<std::size_t>(std::min(ra, rb))][static_cast<std::size_t>(std::max(ra, rb))];
    }
  std::sort(across.begin(), across.end(), [](const ImagePair& x, const ImagePair& y) {
    return x.first != y.first ? x.first < y.first : x.second < y.second;
  });
  out.pairs.insert(out.pairs.end(), across.begin(), across.end());
  return out;
}

}  // namespace arview::mapping
