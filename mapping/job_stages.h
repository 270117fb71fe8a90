#pragma once
// `arview map --engine slurm --slurm-chunk N`: COLMAP's feature extraction and matching as Slurm
// jobs (mapping/slurm_engine.h) of about N frames each, so that a venue's heavy stages spread over
// machines. Internal to mapping/: BuildMap's extract and match stages call them in place of the
// one COLMAP process each.
//
//   extract   <work>/extract/chunk_<k>.txt lists chunk k's frames; job k runs feature_extractor
//             (the command line of the local stage) into a database of its own,
//             <work>/extract/<k>.db. arview, the one writer, then copies chunk 0's database,
//             adds every other chunk's images, keypoints and descriptors to the copy
//             (MergeExtractedImages) and only then puts it in place of <out>/database.db.
//   match     the pairs the local matcher would match (exhaustive or sequential, by name), dealt
//             in order into one block per chunk; job k runs matches_importer --match_type pairs
//             (COLMAP's pair matching and geometric verification) on its own copy of the
//             database, <work>/match/<k>.db; arview then adds each copy's matches and verified
//             pairs to <out>/database.db (MergeVerifiedPairs).
//
// A job is retried once (mapping/slurm_engine.h); a chunk whose database lacks one of its frames'
// descriptors counts as failed. A failed extraction never leaves a half-merged database.db (the
// extract stage then removes the old one, as when the local extractor fails); matching's
// half-added pairs are cleared by the next run's match stage, as for the local matcher. The
// jobs' logs stay in <work>.

#include <filesystem>
#include <string>
#include <vector>

#include "calib/camera.h"
#include "mapping/colmap_pipeline.h"
#include "mapping/pair_matching.h"

namespace arview::mapping {

struct JobStageFiles {
  std::filesystem::path database;    // <out>/database.db
  std::filesystem::path image_root;  // the images COLMAP reads
  std::filesystem::path work;        // the jobs' scripts, lists, databases and logs (<out>/jobs)
};

// The frames' features extracted as one job per chunk of options.slurm_chunk frames, merged into
// files.database (replaced whole). Throws SlurmError, MapError, CancelledError.
void ExtractOnSlurm(const calib::Camera& camera, const MapBuildOptions& options, const JobStageFiles& files,
                    const std::vector<std::string>& names, const MapBuildCallbacks& cb);

// `pairs` (indices into `names`) matched and verified as one job per block, added to
// files.database. Throws SlurmError, MapError, CancelledError.
void MatchOnSlurm(const MapBuildOptions& options, const JobStageFiles& files, const std::vector<std::string>& names,
                  const std::vector<ImagePair>& pairs, const MapBuildCallbacks& cb);

// `items` dealt in order into `parts` runs of sizes differing by at most one (fewer when there
// are fewer items): the [begin, end) of each.
std::vector<std::pair<int, int>> SplitIntoRuns(int items, int parts);

}  // namespace arview::mapping
