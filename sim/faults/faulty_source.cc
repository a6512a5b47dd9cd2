#include "sim/faults/faulty_source.h"

#include <algorithm>
#include <mutex>
#include <numeric>
#include <random>
#include <thread>

#include "pipeline/core/json_fields.h"
#include "pipeline/core/log.h"
#include "sim/faults/frame_damage.h"

namespace px {
namespace {

class FaultySource final : public FrameSource {
 public:
  FaultySource(std::unique_ptr<FrameSource> inner,
               std::vector<FaultSpec> plan,
               std::string field,
               std::optional<LatticeLayout> lattice)
      : inner_(std::move(inner)), plan_(std::move(plan)), field_(std::move(field)), lattice_(std::move(lattice)) {}

  std::string_view Name() const override { return inner_->Name(); }
  SourceDescription Describe() const override { return inner_->Describe(); }

  StatusOr<ConfigureResult> Configure(const SourceConfig& wanted, SourceConfig* granted) override {
    if (gone_ && forever_) {
      return UnavailableError("camera " + inner_->Describe().model + " is gone for good (injected fault: vanish)");
    }
    gone_ = false;  // plugged back in
    return inner_->Configure(wanted, granted);
  }

  StatusOr<FrameSet> Next(std::chrono::milliseconds timeout) override {
    const int capture = ++captures_;
    if (gone_) return UnavailableError("camera disconnected (injected fault: vanish)");
    std::vector<size_t> firing;
    for (size_t i = 0; i < plan_.size(); ++i) {
      if (plan_[i].capture == 0 || plan_[i].capture == capture) firing.push_back(i);
    }
    // The faults that stop the capture as a whole come first: nothing is delivered.
    for (size_t i : firing) {
      const FaultSpec& spec = plan_[i];
      if (spec.kind == FaultKind::kVanish) {
        Logger("faults")->warn("capture {}: injecting {}", capture, DescribeFault(spec));
        gone_ = true;
        forever_ = spec.forever;
        inner_->Stop();
        return UnavailableError("camera disconnected during capture " + std::to_string(capture) +
                                " (injected fault: vanish)");
      }
      if (spec.kind == FaultKind::kStall) {
        Logger("faults")->warn("capture {}: injecting {}", capture, DescribeFault(spec));
        std::this_thread::sleep_for(timeout);
        return DeadlineExceededError("no frame set within " + std::to_string(timeout.count()) +
                                     " ms (injected fault: stall)");
      }
    }
    PX_ASSIGN_OR_RETURN(FrameSet frames, inner_->Next(timeout));
    for (size_t i : firing) {
      const FaultSpec& spec = plan_[i];
      Logger("faults")->warn("capture {}: injecting {}", capture, DescribeFault(spec));
      Status applied = Apply(spec, &frames);
      if (!applied.ok()) return applied.WithContext(json::IndexPath(field_, i));
    }
    return frames;
  }

  void Stop() override { inner_->Stop(); }

 private:
  Status Apply(const FaultSpec& spec, FrameSet* frames) const {
    const bool lattice = frames->kind == FrameSetKind::kLatticeFrame;
    // On a lattice the one sensor frame carries every view; a drop blanks a tile of it.
    const size_t index = lattice ? 0 : static_cast<size_t>(spec.view);
    if (spec.kind != FaultKind::kReorder && index >= frames->frames.size()) {
      return InvalidArgumentError("view " + std::to_string(spec.view) + ": the capture holds " +
                                  std::to_string(frames->frames.size()) + " frame(s)");
    }
    switch (spec.kind) {
      case FaultKind::kTruncate:
        faults::TruncateFrame(spec.keep, &frames->frames[index]);
        return OkStatus();
      case FaultKind::kGarble:
        faults::GarbleFrame(spec.bytes, spec.flagged, spec.seed, &frames->frames[index]);
        return OkStatus();
      case FaultKind::kDrop:
        if (!lattice) {
          faults::DropFrame(&frames->frames[index]);
          return OkStatus();
        }
        return faults::BlankRect(lattice_->tiles[spec.view].rect, &frames->frames[0].image);
      case FaultKind::kReorder: {
        std::vector<Frame>& list = frames->frames;
        if (list.size() < 2) return OkStatus();
        std::vector<size_t> order(list.size());
        std::iota(order.begin(), order.end(), 0);
        std::mt19937_64 random(spec.seed);
        std::shuffle(order.begin(), order.end(), random);
        if (std::is_sorted(order.begin(), order.end())) std::rotate(order.begin(), order.begin() + 1, order.end());
        std::vector<Frame> shuffled;
        for (size_t k : order) shuffled.push_back(std::move(list[k]));
        list = std::move(shuffled);
        return OkStatus();
      }
      case FaultKind::kReformat:
        return faults::ReformatFrame(spec.pixel_format, spec.width, spec.height, &frames->frames[index]);
      case FaultKind::kStall:
      case FaultKind::kVanish:
        break;  // handled before the capture
    }
    return OkStatus();
  }

  std::unique_ptr<FrameSource> inner_;
  std::vector<FaultSpec> plan_;
  std::string field_;
  std::optional<LatticeLayout> lattice_;
  int captures_ = 0;
  bool gone_ = false;
  bool forever_ = false;
};

}  // namespace

StatusOr<std::unique_ptr<FrameSource>> MakeFaultySource(std::unique_ptr<FrameSource> inner,
                                                        std::vector<FaultSpec> plan,
                                                        const std::string& field) {
  if (inner == nullptr) return InvalidArgumentError(field + ": no source to wrap");
  const SourceDescription description = inner->Describe();
  std::optional<LatticeLayout> lattice;
  if (description.rig && description.rig->lattice.rows > 0) lattice = description.rig->lattice;
  for (size_t i = 0; i < plan.size(); ++i) {
    const FaultSpec& spec = plan[i];
    const std::string where = json::IndexPath(field, i);
    PX_RETURN_IF_ERROR(spec.Validate(where));
    if (description.kind != FrameSetKind::kLatticeFrame) continue;
    if (spec.kind == FaultKind::kReorder) {
      return InvalidArgumentError(where + ": reorder needs an image set; " + description.model +
                                  " delivers lattice frames (one sensor frame, nothing to reorder)");
    }
    if (spec.kind == FaultKind::kDrop) {
      if (!lattice) {
        return InvalidArgumentError(where + ": drop on a lattice blanks a tile, but " + description.model +
                                    " describes no lattice layout");
      }
      if (spec.view >= lattice->NumViews()) {
        return InvalidArgumentError(where + ".view: " + std::to_string(spec.view) + " is not a tile of the " +
                                    std::to_string(lattice->rows) + "x" + std::to_string(lattice->cols) + " lattice");
      }
    } else if (spec.view != 0 && spec.kind != FaultKind::kStall && spec.kind != FaultKind::kVanish) {
      return InvalidArgumentError(where + ".view: " + std::to_string(spec.view) +
                                  ", but a lattice capture is one sensor frame (view 0)");
    }
  }
  return std::unique_ptr<FrameSource>(
      std::make_unique<FaultySource>(std::move(inner), std::move(plan), field, std::move(lattice)));
}

}  // namespace px
