#include "device/source_registry.h"

#include <cmath>

#include "drivers/libcamera/libcamera_source.h"
#include "drivers/ptp/usb_ptp_source.h"
#include "drivers/v4l2/v4l2_source.h"
#include "pipeline/core/log.h"
#include "sim/faults/faulty_source.h"
#include "sim/replay/replay_source.h"
#include "sim/synthetic/synthetic_source.h"

namespace px::device {

std::vector<std::string> KnownSourceKinds() { return {"sim", "replay", "libcamera", "v4l2", "ptp"}; }

StatusOr<SimCameraSpec> SimCameraFromSettings(const SimSourceSettings& settings) {
  SimCameraSpec spec;
  if (settings.camera == "pop9") {
    spec = SimCameraSpec::Pop9();
  } else if (settings.camera == "integral5x4") {
    spec = SimCameraSpec::Integral5x4();
  } else {
    return InvalidArgumentError("source.sim.camera: '" + settings.camera + "' is not one of pop9, integral5x4");
  }
  const int preset_width = spec.tile_width;
  const int preset_height = spec.tile_height;
  int width = settings.tile_width;
  int height = settings.tile_height;
  if (width == 0 && height > 0) width = static_cast<int>(std::lround(preset_width * double(height) / preset_height));
  if (height == 0 && width > 0) height = static_cast<int>(std::lround(preset_height * double(width) / preset_width));
  if (width > 0) {
    spec.focal_px *= static_cast<double>(width) / preset_width;
    spec.tile_width = width;
    spec.tile_height = height;
    spec.name += "-" + std::to_string(width) + "x" + std::to_string(height);
  }
  if (Status valid = spec.Validate(); !valid.ok()) return valid.WithContext("source.sim");
  return spec;
}

// One frame of `width` x `height` in the named pixel format; errors name `field`.
static StatusOr<SourceConfig> WantedSingleFrame(const std::string& field,
                                                const std::string& pixel_format,
                                                int width,
                                                int height) {
  std::optional<PixelFormat> format = ParsePixelFormat(pixel_format);
  if (!format) return InvalidArgumentError(field + ": '" + pixel_format + "' is not a known pixel format");
  return SourceConfig{*format, width, height, 1};
}

// The configured source itself, before source.faults are wrapped around it.
static StatusOr<OpenedSource> OpenBareSource(const SourceSettings& settings) {
  OpenedSource opened;
  if (settings.kind == "sim") {
    SyntheticSourceOptions options;
    PX_ASSIGN_OR_RETURN(options.camera, SimCameraFromSettings(settings.sim));
    options.scene_file = settings.sim.scene;
    options.seed = settings.sim.seed;
    auto source = MakeSyntheticSource(options);
    if (!source.ok()) return source.status().WithContext("source.sim");
    opened.source = std::move(source).value();
    // The sensor's native size in the camera's own pixel format.
    SourceConfig wanted;
    wanted.pixel_format = options.camera.pixel_format;
    wanted.shots = 1;
    opened.wanted = wanted;
    return opened;
  }
  if (settings.kind == "replay") {
    ReplayOptions options;
    options.loop = settings.replay.loop;
    auto source = OpenReplaySource(settings.replay.path, options);
    if (!source.ok()) return source.status().WithContext("source.replay.path");
    opened.source = std::move(source).value();
    return opened;
  }
  if (settings.kind == "libcamera") {
    libcamera_driver::LibcameraOptions options;
    options.camera_id = settings.libcamera.camera;
    options.rig_calibration = settings.libcamera.rig_calibration;
    auto source = libcamera_driver::OpenLibcameraSource(options);
    if (!source.ok()) return source.status().WithContext("source.libcamera.rig_calibration");
    opened.source = std::move(source).value();
    PX_ASSIGN_OR_RETURN(opened.wanted,
                        WantedSingleFrame("source.libcamera.pixel_format",
                                          settings.libcamera.pixel_format,
                                          settings.libcamera.width,
                                          settings.libcamera.height));
    return opened;
  }
  if (settings.kind == "v4l2") {
    V4l2SourceOptions options;
    options.device = settings.v4l2.device;
    options.rig_calibration = settings.v4l2.rig_calibration;
    if (settings.v4l2.exposure >= 0) options.controls.exposure = settings.v4l2.exposure;
    if (settings.v4l2.gain >= 0) options.controls.gain = settings.v4l2.gain;
    auto source = OpenV4l2Source(options);
    if (!source.ok()) return source.status().WithContext("source.v4l2");
    opened.source = std::move(source).value();
    PX_ASSIGN_OR_RETURN(
        opened.wanted,
        WantedSingleFrame(
            "source.v4l2.pixel_format", settings.v4l2.pixel_format, settings.v4l2.width, settings.v4l2.height));
    return opened;
  }
  if (settings.kind == "ptp") {
    UsbPtpSourceOptions options;
    options.vendor_id = settings.ptp.vendor_id;
    options.product_id = settings.ptp.product_id;
    options.shot_timeout = std::chrono::milliseconds(settings.ptp.timeout_ms);
    auto source = OpenUsbPtpSource(options);
    if (!source.ok()) return source.status().WithContext("source.ptp");
    opened.source = std::move(source).value();
    // Hand-held shots as the camera makes them, decoded to RGB.
    opened.wanted = SourceConfig{PixelFormat::kRgb888, 0, 0, settings.ptp.shots};
    return opened;
  }
  return InvalidArgumentError("source.kind: '" + settings.kind + "' is not one of sim, replay, libcamera, v4l2, ptp");
}

StatusOr<OpenedSource> OpenSource(const SourceSettings& settings) {
  PX_ASSIGN_OR_RETURN(OpenedSource opened, OpenBareSource(settings));
  if (settings.faults.empty()) return opened;
  for (const FaultSpec& fault : settings.faults) {
    Logger("device")->warn("source.faults: injecting {} into source {}", DescribeFault(fault), opened.source->Name());
  }
  PX_ASSIGN_OR_RETURN(opened.source, MakeFaultySource(std::move(opened.source), settings.faults, "source.faults"));
  return opened;
}

}  // namespace px::device
