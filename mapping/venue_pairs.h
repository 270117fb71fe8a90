#pragma once
// The pairs a venue's frames are matched in (issue 55): within each room (recording) as one
// recording's are, exhaustive or sequential, and across rooms from a descriptor index, as
// `arview map extend` picks the old keyframes a new session is matched with. Recordings of one
// venue are rarely walked one into the next: a sequence over their frames one after another
// would pair a room's last frames with the next room's first, wherever those stood, and never
// the frames that look through the same door. Each frame is instead paired with the frames of
// the other rooms that own the nearest neighbours of most of its descriptors (a ratio test over
// each room's index), with enough of them to be worth COLMAP's verification.

#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "base/cancellation.h"
#include "base/option_check.h"
#include "mapping/pair_matching.h"

namespace arview::mapping {

struct CrossRoomOptions {
  // Frames of other rooms each frame is paired with (most votes first); 0: the rooms are matched
  // as one sequence of frames, room after room, as before (recordings walked one into the next).
  int neighbours = 5;
  // Descriptors of each frame put in its room's index and queried with, taken evenly from its
  // own (2,048 of 8,192 frames' worth would cost minutes for a 600-frame venue on two cores).
  int descriptors_per_frame = 400;
  // Of them, how many must vote for a frame (their nearest neighbour there, passing the ratio
  // test) for the pair to be matched: unrelated frames get a few chance votes.
  int min_votes = 12;
  double max_ratio = 0.8;  // nearest over second-nearest distance within the other room
  int threads = 2;         // frames queried at once (-1: every core)

  // Throws OptionError naming the first bad field (base/option_check.h).
  void Check(const OptionNames& names = {}) const;
};

// The pairs and what they hold, for the note the map prints.
struct VenuePairs {
  std::vector<ImagePair> pairs;  // within each room, then across rooms; each once, first < second
  int within = 0;                // of them, within a room
  // across[a][b] (a < b): pairs between room a and room b.
  std::vector<std::vector<int>> across;

  // "1,930 pairs within rooms, 612 across: room-1 and room-2 301, room-2 and room-3 311"; each
  // room that shares no pair with another named ("room-4 shares no frame with the others: it will
  // be mapped apart, or not at all").
  std::string Describe(const std::vector<std::string>& room_names) const;
};

// `room_of[i]` is image i's room (0 .. rooms-1; images of a room need not be contiguous), each
// image's descriptors `descriptors[i]` (N x 128 CV_8U, COLMAP's convention; may be empty),
// `within(n)` the pairs of a room's n images in their order (exhaustive or sequential).
// `progress(done, total)` is called from this thread as images are queried; `cancel` is looked
// at between images (CancelledError).
VenuePairs PairVenueFrames(const std::vector<int>& room_of, const std::vector<cv::Mat>& descriptors,
                           const std::function<std::vector<ImagePair>(int images)>& within,
                           const CrossRoomOptions& options, const std::function<void(int, int)>& progress = {},
                           const CancellationToken& cancel = {});

}  // namespace arview::mapping
