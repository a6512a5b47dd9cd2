// px_sim_render: renders a scene through a simulated lattice camera and writes what it made,
// for looking at scenes while writing them and for timing the ray caster.
//   px_sim_render SCENE.json OUT_DIR [pop9|integral5x4] [--threads N] [--distort] [--seed S]
// Writes sensor.png (the raw sensor as BGR), view_NN.png (clean upright views) and
// depth_NN.png (depth, 0..5 m -> 0..255) and prints the render time.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "sim/synthetic/scene_json.h"
#include "sim/synthetic/sim_sensor.h"

namespace {

int Usage() {
  std::fprintf(stderr,
               "usage: px_sim_render SCENE.json OUT_DIR [pop9|integral5x4] [--threads N] [--distort] [--seed S]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) return Usage();
  const std::filesystem::path scene_file = argv[1], out_dir = argv[2];
  px::SimCameraSpec spec = px::SimCameraSpec::Pop9();
  uint64_t seed = 1;
  for (int i = 3; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "pop9") {
      spec = px::SimCameraSpec::Pop9();
    } else if (arg == "integral5x4") {
      spec = px::SimCameraSpec::Integral5x4();
    } else if (arg == "--distort") {
      spec.distortion = {-0.12, 0.03, 0.0005, -0.0003, 0};
    } else if (arg == "--threads" && i + 1 < argc) {
      cv::setNumThreads(std::stoi(argv[++i]));
    } else if (arg == "--seed" && i + 1 < argc) {
      seed = std::stoull(argv[++i]);
    } else {
      return Usage();
    }
  }
  spec.noise_sigma = 2.0;
  spec.vignetting = 0.3;
  spec.exposure_spread = 0.05;
  auto scene = px::sim::LoadScene(scene_file);
  if (!scene.ok()) {
    std::fprintf(stderr, "%s\n", scene.status().ToString().c_str());
    return 1;
  }
  const auto start = std::chrono::steady_clock::now();
  auto frame = px::sim::RenderSensorFrame(*scene, spec, seed);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (!frame.ok()) {
    std::fprintf(stderr, "%s\n", frame.status().ToString().c_str());
    return 1;
  }
  std::printf("%s through %s (%d threads): %.0f ms\n", scene->name.c_str(), spec.name.c_str(), cv::getNumThreads(), ms);
  std::filesystem::create_directories(out_dir);
  auto sensor = px::ToBgr(frame->sensor);
  if (sensor.ok()) cv::imwrite((out_dir / "sensor.png").string(), *sensor);
  for (const px::sim::ViewTruth& view : frame->truth.views) {
    char name[32];
    std::snprintf(name, sizeof(name), "view_%02d.png", view.id.value);
    cv::imwrite((out_dir / name).string(), view.bgr);
    cv::Mat depth8;
    view.depth_m.convertTo(depth8, CV_8U, 255.0 / 5.0);
    std::snprintf(name, sizeof(name), "depth_%02d.png", view.id.value);
    cv::imwrite((out_dir / name).string(), depth8);
  }
  return 0;
}
