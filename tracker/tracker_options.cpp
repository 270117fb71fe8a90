// The tracker's options check themselves (base/option_check.h): each struct its own fields, then
// its members' through their own Check(). The bounds are what the steps need to work at all
// (a threshold above 0, a ratio in (0, 1]); what is sensible is the flags' ranges (arview track).

#include <cmath>

#include "tracker/tracker.h"

namespace arview::tracker {

namespace {

// "0 (what it means) or at least 64": sizes of the image a step works on.
void RequireSideOrZero(int side, const std::string& name, const std::string& zero_means) {
  RequireOption(side == 0 || side >= 64, name, "0 (" + zero_means + ") or at least 64", side);
}

void RequireRatio(double ratio, const std::string& name) { RequireOption(ratio > 0 && ratio <= 1, name, "in (0, 1]", ratio); }

}  // namespace

void FeatureOptions::Check(const OptionNames& names) const {
  RequireOption(max_features >= 0, names("max_features"), "0 (all) or more", max_features);
  RequireOption(octave_layers >= 1, names("octave_layers"), "at least 1", octave_layers);
  RequireOption(contrast_threshold > 0, names("contrast_threshold"), "above 0", contrast_threshold);
  RequireOption(edge_threshold > 0, names("edge_threshold"), "above 0", edge_threshold);
  RequireOption(sigma > 0, names("sigma"), "above 0", sigma);
}

void MatchOptions::Check(const OptionNames& names) const {
  RequireRatio(ratio, names("ratio"));
  // The second neighbour is often the same map point: the nearest other is looked for among knn.
  RequireOption(knn >= 2, names("knn"), "at least 2", knn);
}

void AbsolutePoseOptions::Check(const OptionNames& names) const {
  RequireOption(ransac_threshold_px > 0, names("ransac_threshold_px"), "above 0", ransac_threshold_px);
  RequireOption(ransac_max_iterations >= 1, names("ransac_max_iterations"), "at least 1", ransac_max_iterations);
  RequireOption(ransac_success_probability > 0 && ransac_success_probability < 1, names("ransac_success_probability"),
                "in (0, 1)", ransac_success_probability);
  RequireOption(prior_loss_scale_px > 0, names("prior_loss_scale_px"), "above 0", prior_loss_scale_px);
  RequireOption(inlier_threshold_px > 0, names("inlier_threshold_px"), "above 0", inlier_threshold_px);
  RequireOption(refinement.loss_scale_px > 0, names("refinement.loss_scale_px"), "above 0", refinement.loss_scale_px);
  // Six degrees of freedom, two residuals a point.
  RequireOption(min_inliers >= 3, names("min_inliers"), "at least 3", min_inliers);
  RequireOption(max_rms_px > 0, names("max_rms_px"), "above 0", max_rms_px);
  RequireOption(min_collinearity_ratio >= 0, names("min_collinearity_ratio"), "0 or more", min_collinearity_ratio);
}

void RelocalizerOptions::Check(const OptionNames& names) const {
  features.Check(names.Nested("features"));
  reduced_features.Check(names.Nested("reduced_features"));
  RequireSideOrZero(sift_long_side, names("sift_long_side"), "the working resolution");
  RequireSideOrZero(reloc_sift_long_side, names("reloc_sift_long_side"), "as " + names("sift_long_side"));
  RequireOption(sift_own_size_up_to >= 0, names("sift_own_size_up_to"), "0 or more", sift_own_size_up_to);
  matching.Check(names.Nested("matching"));
  RequireOption(keyframe_matching >= 0, names("keyframe_matching"), "0 or more", keyframe_matching);
  RequireOption(keyframe_knn >= 2, names("keyframe_knn"), "at least 2", keyframe_knn);
  pose.Check(names.Nested("pose"));
}

void OneEuroOptions::Check(const OptionNames& names) const {
  RequireOption(min_cutoff_hz > 0, names("min_cutoff_hz"), "above 0", min_cutoff_hz);
  RequireOption(beta >= 0, names("beta"), "0 or more", beta);
  RequireOption(derivative_cutoff_hz > 0, names("derivative_cutoff_hz"), "above 0", derivative_cutoff_hz);
}

void TrackingOptions::Check(const OptionNames& names) const {
  RequireOption(lk_window_px >= 3, names("lk_window_px"), "at least 3", lk_window_px);
  RequireOption(lk_pyramid_levels >= 0, names("lk_pyramid_levels"), "0 or more", lk_pyramid_levels);
  RequireOption(lk_max_iterations >= 1, names("lk_max_iterations"), "at least 1", lk_max_iterations);
  RequireOption(max_flow_tracks >= 1, names("max_flow_tracks"), "at least 1", max_flow_tracks);
  RequireOption(replenish_below >= 0, names("replenish_below"), "0 or more", replenish_below);
  RequireOption(guided_radius_px > 0, names("guided_radius_px"), "above 0", guided_radius_px);
  RequireOption(guided_radius_predicted_px > 0, names("guided_radius_predicted_px"), "above 0", guided_radius_predicted_px);
  RequireRatio(guided_ratio, names("guided_ratio"));
  RequireOption(guided_max_features >= 0, names("guided_max_features"), "0 (all) or more", guided_max_features);
  RequireOption(guided_contrast_threshold > 0, names("guided_contrast_threshold"), "above 0", guided_contrast_threshold);
  RequireOption(prefetch_below >= 0, names("prefetch_below"), "0 (off) or more", prefetch_below);
  RequireOption(prefetch_lag_frames >= 1, names("prefetch_lag_frames"), "at least 1", prefetch_lag_frames);
  // With the worker nothing on the tracking thread extracts SIFT: guided matching has only what
  // is extracted ahead.
  if (background && prefetch_below == 0) {
    throw OptionError(names("prefetch_below") + " 0 needs " + names("background") +
                      " off: with the worker, guided matching's SIFT is extracted only ahead");
  }
  RequireOption(ransac_max_iterations >= 1, names("ransac_max_iterations"), "at least 1", ransac_max_iterations);
  RequireOption(ransac_threshold_px > 0, names("ransac_threshold_px"), "above 0", ransac_threshold_px);
  RequireOption(refine_loss_scale_px > 0, names("refine_loss_scale_px"), "above 0", refine_loss_scale_px);
  RequireOption(min_inliers >= 3, names("min_inliers"), "at least 3", min_inliers);
  RequireOption(wide_radius_fraction >= 0, names("wide_radius_fraction"), "0 (off) or more", wide_radius_fraction);
  RequireRatio(wide_ratio, names("wide_ratio"));
  RequireOption(wide_ransac_iterations >= 1, names("wide_ransac_iterations"), "at least 1", wide_ransac_iterations);
  RequireOption(max_prediction_ratio >= 1, names("max_prediction_ratio"), "at least 1", max_prediction_ratio);
  RequireOption(align_max_seconds >= 0, names("align_max_seconds"), "0 (off) or more", align_max_seconds);
  RequireOption(!std::isnan(fresh_features_after_s), names("fresh_features_after_s"), "a number (negative: never)",
                fresh_features_after_s);
  RequireOption(flow_brightness_tolerance >= 0, names("flow_brightness_tolerance"), "0 or more", flow_brightness_tolerance);
  RequireOption(light_switch_ev > 0, names("light_switch_ev"), "above 0", light_switch_ev);
  RequireOption(light_switch_hold_s >= 0, names("light_switch_hold_s"), "0 or more", light_switch_hold_s);
  moving.Check(names.Nested("moving"));
  hidden.Check(names.Nested("hidden"));
  research.Check(names.Nested("research"));
  clipped.Check(names.Nested("clipped"));
}

void TrackerOptions::Check(const OptionNames& names) const {
  RequireSideOrZero(working_long_side, names("working_long_side"), "full resolution");
  relocalization.Check(names.Nested("relocalization"));
  tracking.Check(names.Nested("tracking"));
  smoothing.Check(names.Nested("smoothing"));
  RequireOption(index.checks >= 1, names("index.checks"), "at least 1", index.checks);
  RequireOption(min_map_points >= 3, names("min_map_points"), "at least 3", min_map_points);
}

}  // namespace arview::tracker
