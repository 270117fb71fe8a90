#pragma once
// arview's own feature matching for `arview map`: the frames' SIFT descriptors (extracted by
// COLMAP into its database) matched pair by pair with a FLANN kd-tree built once per image, in
// parallel, with COLMAP's tests (ratio, largest distance, mutual best). The candidate matches
// then go to COLMAP (`colmap matches_importer --match_type raw`) for its geometric verification,
// which is what the mapper reads. COLMAP's own CPU matcher builds a new kd-tree for every pair
// and image and verifies in the same pass; on phone-fox's 34 frames (561 pairs, 8,192
// features a frame) it took 195-217 s where these kd-trees, kept per image, take about a third
// of that (docs/mapping.md, "Matching").

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "base/cancellation.h"

namespace arview::mapping {

// Two images by their place in the image list, first < second.
struct ImagePair {
  int first = 0;
  int second = 0;
  bool operator==(const ImagePair&) const = default;
};

// Every pair of `images` images, (0,1), (0,2), ... (n-2,n-1).
std::vector<ImagePair> ExhaustivePairs(int images);

// COLMAP's sequential pairs (SequentialMatching): each image with the next `overlap` images and,
// with `quadratic`, also with the images 2^k after it for k < overlap (long links that close
// loops along a video). Each pair once, in order.
std::vector<ImagePair> SequentialPairs(int images, int overlap, bool quadratic);

// Worker threads for `jobs` jobs: `threads`, or every core when `threads` <= 0, at most one a job.
int Workers(int threads, size_t jobs);

// Runs job(i) for i in [0, count) on `workers` threads; the calling thread reports
// progress(done, count) and looks at `cancel` (then CancelledError "interrupted: <what>"). The
// first exception of a job is rethrown after every worker has stopped.
void ForEachInParallel(size_t count, int workers, const std::function<void(size_t)>& job,
                       const std::function<void(int, int)>& progress, const CancellationToken& cancel,
                       const std::string& what);

struct PairMatchingOptions {
  // COLMAP's SiftMatching defaults: the best neighbour's distance at most max_ratio of the
  // second's, at most max_distance (on unit descriptors; COLMAP stores them x512 as bytes), and
  // each the other's best (cross check).
  double max_ratio = 0.8;
  double max_distance = 0.7;
  bool cross_check = true;
  // The kd-trees: 4 randomized trees, 32 leaves visited per query. 64 leaves found 2% more
  // matches on phone-fox and took 1.8x as long; the verified pairs and the map were the same
  // (docs/mapping.md, "Matching").
  int trees = 4;
  int checks = 32;
  // A pair with fewer matches is given none: COLMAP's verification needs this many inliers
  // (SiftMatching.min_num_inliers) and would only spend time on it (on templeRing 478 of the
  // 1,081 pairs with a match had fewer).
  int min_matches = 15;
  int threads = 2;  // workers matching pairs (-1: every core)
};

// The matches of one pair: rows of the first image's descriptors with rows of the second's.
struct PairMatches {
  ImagePair pair;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> matches;
};

// Matches `pairs` of `descriptors` (one CV_8U N x 128 matrix per image, COLMAP's convention).
// `progress(done, total)` is called as pairs finish (from the calling thread); `cancel` is
// looked at between pairs (CancelledError). The result is in the order of `pairs` and does not
// depend on the number of threads.
std::vector<PairMatches> MatchImagePairs(const std::vector<cv::Mat>& descriptors, const std::vector<ImagePair>& pairs,
                                         const PairMatchingOptions& options,
                                         const std::function<void(int done, int total)>& progress = {},
                                         const CancellationToken& cancel = {});

// COLMAP's raw match list (matches_importer --match_type raw): per pair its two image names on
// one line, one "row1 row2" line per match, and an empty line. `parts` files, the pairs dealt
// out in turn so that each part holds about as many matches; pairs without a match are left out.
// Throws MapError when a file cannot be written.
void WriteMatchLists(const std::vector<std::string>& names, const std::vector<PairMatches>& matches,
                     const std::vector<std::filesystem::path>& parts);

// Copies the matches and two-view geometries of the COLMAP database `part` into `database`
// (the pairs verified in a copy of it). Throws MapError naming the database that fails.
void MergeVerifiedPairs(const std::filesystem::path& database, const std::filesystem::path& part);

// Copies the images, keypoints and descriptors of the COLMAP database `part` (feature_extractor
// run on other images with the same camera) into `database`, the part's image ids moved past the
// database's; the part is changed too (it is a job's, removed after). Throws MapError when the
// part's camera is not the database's one camera, an image name is in both, or a file fails.
void MergeExtractedImages(const std::filesystem::path& database, const std::filesystem::path& part);

}  // namespace arview::mapping
