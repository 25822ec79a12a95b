#include "synth/session_writer.h"

#include <fstream>
#include <string>

#include "imagefile/image_file.h"
#include "io/errors.h"
#include "io/trace.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;
constexpr const char* kSubfolders[] = {"calibration", "runs", "traces"};

// As cv::imwrite wrote it, by the file's extension: JPEG at the photo's
// quality, PNG at zlib level 6, TIFF as OpenCV wrote it.
void WritePhoto(const fs::path& folder, const SessionPhoto& photo) {
  const fs::path path = folder / photo.file;
  imagefile::EncodeOptions options;
  if (photo.jpeg_quality > 0) {
    options.jpeg_quality = photo.jpeg_quality;
  } else {
    options.png_compression = 6;
  }
  imagefile::Bytes bytes;
  std::string problem;
  if (!imagefile::EncodeForExtension(path.extension().string(), photo.image, options, &bytes,
                                     &problem)) {
    throw InputError({path, "", std::nullopt}, "cannot write the photo: " + problem);
  }
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  if (!out.flush()) throw InputError({path, "", std::nullopt}, "cannot write the photo");
}

}  // namespace

void CreateSessionFolder(const fs::path& folder) {
  std::error_code ec;
  if (fs::exists(folder) && !fs::is_empty(folder, ec)) {
    throw InputError({folder, "", std::nullopt}, "the output folder exists and is not empty");
  }
  for (const char* sub : kSubfolders) {
    fs::create_directories(folder / sub, ec);
    if (ec) throw InputError({folder / sub, "", std::nullopt}, "cannot create the folder");
  }
}

void WriteCsvTraces(const fs::path& folder, const RunPlan& plan, const SimulatedRun& run) {
  for (std::size_t i = 0; i < plan.calibrations.size(); ++i) {
    if (const auto& file = plan.calibrations[i].csv_file) {
      const ScopeTrace& trace = run.calibrations[i].trace;
      WriteTraceCsv(folder / *file, Trace{trace.time_s, trace.volts, {}});
    }
  }
  for (const auto& [name, file] : plan.csv_files) {
    if (name == "contact") {
      WriteTraceCsv(folder / file, run.contact_samples);
    } else {
      const ScopeTrace& trace = name == "right" ? run.right : run.left;
      WriteTraceCsv(folder / file, Trace{trace.time_s, trace.volts, {}});
    }
  }
}

void WritePhotos(const fs::path& folder, const RunPhotos& photos) {
  for (const auto& photo : photos.calibrations) {
    if (photo) WritePhoto(folder, *photo);
  }
  if (photos.run) WritePhoto(folder, *photos.run);
}

void FinishSessionFolder(const fs::path& folder, const SessionManifest& manifest) {
  WriteManifest(folder / "session.toml", manifest);
  std::error_code ec;
  for (const char* sub : kSubfolders) {
    if (fs::is_empty(folder / sub, ec)) fs::remove(folder / sub, ec);
  }
}

}  // namespace impactlab
