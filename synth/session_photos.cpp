#include "synth/session_photos.h"

#include <algorithm>

#include "render/oscillograph.h"
#include "synth/randomised_photo.h"

namespace impactlab {
namespace {

nlohmann::json PhotoTruth(const std::string& file, const RenderedPhoto& photo) {
  const CameraMapping& m = photo.mapping;
  nlohmann::json traces = nlohmann::json::array();
  for (const TraceTruth& t : photo.traces) {
    nlohmann::json points = nlohmann::json::array();
    const std::size_t stride = std::max<std::size_t>(1, t.time_s.size() / 400);
    for (std::size_t i = 0; i < t.time_s.size(); i += stride) {
      points.push_back({t.time_s[i], t.centre_px[i].x, t.centre_px[i].y});
    }
    traces.push_back({{"name", t.name}, {"points_t_x_y_px", points}});
  }
  return {{"file", file},
          {"width_px", photo.image.cols},
          {"height_px", photo.image.rows},
          {"mapping",
           {{"homography",
             {m.homography(0, 0), m.homography(0, 1), m.homography(0, 2), m.homography(1, 0),
              m.homography(1, 1), m.homography(1, 2), m.homography(2, 0), m.homography(2, 1),
              m.homography(2, 2)}},
            {"radial_k1", m.radial_k1},
            {"distortion_centre_px", {m.distortion_centre_px.x, m.distortion_centre_px.y}},
            {"distortion_radius_px", m.distortion_radius_px}}},
          {"traces", traces}};
}

// `bands`: a run photo's, for the randomised style's truth.
SessionPhoto Photograph(const OscillographScene& scene, const PhotoPlan& plan,
                        const SynthOptions& options, const RunBands* bands) {
  RenderOptions render;
  render.style = options.style;
  const bool randomised = plan.look.has_value();
  // The randomised style draws its own size unless one is asked for.
  render.width_px = options.width_px > 0 ? options.width_px
                    : randomised         ? 0
                                         : (options.preset == "quick" ? 1000 : 0);
  render.seed = plan.render_seed;
  render.handling = options.photo_handling;
  // A real chopper switches at ~100 kHz, invisible at 0.5 s/div: 0.01 div
  // slots (a pixel or two) draw the traces chopped but nearly continuous, as
  // such a photo shows them. Long dashes would hide rebound peaks in the gaps.
  render.chop_dash_div = 0.01;
  // The randomised style draws the chopper anywhere from that to long dashes.
  if (randomised) ApplyBeamLook(*plan.look, render);
  RenderedPhoto photo = RenderOscillograph(scene, render);

  // Prints and phone pictures come as JPEG; the others as lossless PNG. A
  // randomised photo is stored as it was drawn: JPEG at its own quality, else
  // PNG or (one in four) TIFF, 8 or 16 bits.
  bool jpeg = options.style == PhotoStyle::kPolaroid || options.style == PhotoStyle::kPhone ||
              options.style == PhotoStyle::kLowres || options.style == PhotoStyle::kDigital;
  // A digital scope's photo was taken by a phone at its own quality.
  int quality = options.style == PhotoStyle::kDigital ? photo.jpeg_quality : 90;
  std::string lossless_extension = ".png";
  if (randomised) {
    jpeg = photo.jpeg_quality > 0;
    quality = photo.jpeg_quality;
    if (jpeg && photo.image.depth() == CV_16U) photo.image.convertTo(photo.image, CV_8U, 1.0 / 257);
    if (plan.tiff_if_lossless) lossless_extension = ".tif";
  }
  SessionPhoto out;
  out.file = plan.stem + (jpeg ? ".jpg" : lossless_extension);
  out.jpeg_quality = jpeg ? quality : 0;
  out.truth = PhotoTruth(out.file, photo);
  if (randomised) out.truth["look"] = LookJson(photo, *plan.look, bands, scene.divisions);
  out.image = std::move(photo.image);
  return out;
}

SessionPhoto PhotographCalibration(const CalibrationPlan& plan, const ScopeTrace& trace,
                                   const SynthOptions& options) {
  OscillographScene scene;
  scene.traces.push_back(
      {"calibration", trace.time_s, trace.volts, trace.settings, BeamMode::kContinuous, 0});
  if (plan.photo->look) scene.traces.back().brightness = plan.photo->look->contact_brightness;
  return Photograph(scene, *plan.photo, options, nullptr);
}

// Right and left chopped on one beam over the slow sweep, the contact step on
// the second beam's fast delayed sweep.
SessionPhoto PhotographRunTraces(const RunPlan& plan, const SimulatedRun& run,
                                 const SynthOptions& options) {
  OscillographScene scene;
  scene.traces.push_back(
      {"right", run.right.time_s, run.right.volts, run.right.settings, BeamMode::kChopped, 0});
  scene.traces.push_back(
      {"left", run.left.time_s, run.left.volts, run.left.settings, BeamMode::kChopped, 0});
  scene.traces.push_back({"contact", run.contact.time_s, run.contact.volts, run.contact.settings,
                          BeamMode::kContinuous, 1});
  if (const auto& look = plan.photo->look) {
    scene.traces[0].brightness = scene.traces[1].brightness = look->slow_brightness;
    scene.traces[2].brightness = look->contact_brightness;
  }
  return Photograph(scene, *plan.photo, options, &plan.bands);
}

}  // namespace

RunPhotos PhotographRun(const RunPlan& plan, const SimulatedRun& run, const SynthOptions& options) {
  RunPhotos photos;
  for (std::size_t i = 0; i < plan.calibrations.size(); ++i) {
    const CalibrationPlan& calibration = plan.calibrations[i];
    photos.calibrations.push_back(
        calibration.photo
            ? std::optional(PhotographCalibration(calibration, run.calibrations[i].trace, options))
            : std::nullopt);
  }
  if (plan.photo) photos.run = PhotographRunTraces(plan, run, options);
  return photos;
}

}  // namespace impactlab
