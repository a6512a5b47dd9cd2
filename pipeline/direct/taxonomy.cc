#include "pipeline/direct/taxonomy.h"

#include <algorithm>
#include <random>

namespace px::direct {

namespace {

// Draws an index in [0, n) from a generator whose output is fixed by the standard for a seed
// (std::uniform_int_distribution is not: its results differ between standard libraries).
size_t Draw(std::mt19937_64& rng, size_t n) { return n <= 1 ? 0 : static_cast<size_t>(rng() % n); }

std::vector<Move> MovesOfRow(int row) {
  std::vector<Move> moves;
  for (Move move : AllMoves()) {
    if (SubjectsNeeded(move) == row) moves.push_back(move);
  }
  return moves;
}

std::string Join(const std::vector<Move>& moves) {
  std::string text;
  for (Move move : moves) text += (text.empty() ? "" : ", ") + std::string(MoveName(move));
  return text;
}

}  // namespace

std::string_view MoveName(Move move) {
  switch (move) {
    case Move::kEstablishingDolly:
      return "establishing_dolly";
    case Move::kEstablishingDollyOut:
      return "establishing_dolly_out";
    case Move::kDollyIn:
      return "dolly_in";
    case Move::kDollyOut:
      return "dolly_out";
    case Move::kDollyZoomOut:
      return "dolly_zoom_out";
    case Move::kDollyZoomIn:
      return "dolly_zoom_in";
    case Move::kDolly:
      return "dolly";
  }
  return "unknown";
}

std::string_view EffectName(Effect effect) {
  switch (effect) {
    case Effect::kNone:
      return "none";
    case Effect::kDofChange:
      return "dof_change";
    case Effect::kFocusPull:
      return "focus_pull";
    case Effect::kSaturation:
      return "saturation";
    case Effect::kBrightness:
      return "brightness";
    case Effect::kDesaturateBackground:
      return "desaturate_background";
    case Effect::kDimBackground:
      return "dim_background";
  }
  return "unknown";
}

const std::vector<Move>& AllMoves() {
  static const std::vector<Move> moves = {Move::kEstablishingDolly,
                                          Move::kEstablishingDollyOut,
                                          Move::kDollyIn,
                                          Move::kDollyOut,
                                          Move::kDollyZoomOut,
                                          Move::kDollyZoomIn,
                                          Move::kDolly};
  return moves;
}

const std::vector<Effect>& AllEffects() {
  static const std::vector<Effect> effects = {Effect::kNone,
                                              Effect::kDofChange,
                                              Effect::kFocusPull,
                                              Effect::kSaturation,
                                              Effect::kBrightness,
                                              Effect::kDesaturateBackground,
                                              Effect::kDimBackground};
  return effects;
}

StatusOr<Move> ParseMove(std::string_view name) {
  for (Move move : AllMoves()) {
    if (name == MoveName(move)) return move;
  }
  return InvalidArgumentError("move '" + std::string(name) + "' is not one of " + Join(AllMoves()));
}

StatusOr<Effect> ParseEffect(std::string_view name) {
  std::string known;
  for (Effect effect : AllEffects()) {
    if (name == EffectName(effect)) return effect;
    known += (known.empty() ? "" : ", ") + std::string(EffectName(effect));
  }
  return InvalidArgumentError("effect '" + std::string(name) + "' is not one of " + known);
}

int SubjectsNeeded(Move move) {
  switch (move) {
    case Move::kEstablishingDolly:
    case Move::kEstablishingDollyOut:
      return 0;
    case Move::kDollyIn:
    case Move::kDollyOut:
    case Move::kDollyZoomOut:
    case Move::kDollyZoomIn:
      return 1;
    case Move::kDolly:
      return 2;
  }
  return 0;
}

bool EffectSuits(Move move, Effect effect) {
  if (effect == Effect::kNone) return true;
  const int subjects = SubjectsNeeded(move);
  if (effect == Effect::kFocusPull) return subjects >= 2;
  return subjects >= 1;
}

std::vector<Effect> AutomaticEffects(Move move) {
  switch (SubjectsNeeded(move)) {
    case 0:
      return {Effect::kNone};
    case 1:
      return {Effect::kNone, Effect::kDofChange};
    default:
      return {Effect::kNone, Effect::kFocusPull, Effect::kDofChange};
  }
}

StatusOr<MoveChoice> ChooseMove(int num_subjects,
                                const std::string& requested_move,
                                const std::string& requested_effect,
                                uint64_t seed) {
  std::mt19937_64 rng(seed);
  const int row = std::clamp(num_subjects, 0, 2);
  MoveChoice choice;
  const std::string count = std::to_string(num_subjects) + (num_subjects == 1 ? " subject" : " subjects");
  bool drawn = requested_move == "auto";
  if (requested_move == "dolly_zoom") {
    if (row >= 1) {
      choice.move = Draw(rng, 2) == 0 ? Move::kDollyZoomOut : Move::kDollyZoomIn;
      choice.reason = "requested dolly_zoom, direction drawn with seed " + std::to_string(seed) + ": " +
                      std::string(MoveName(choice.move));
    } else {
      choice.reason = "requested dolly_zoom needs a subject, found none; ";
      drawn = true;
    }
  } else if (!drawn) {
    PX_ASSIGN_OR_RETURN(Move move, ParseMove(requested_move));
    if (SubjectsNeeded(move) <= num_subjects) {
      choice.move = move;
      choice.reason = "requested " + requested_move + " (" + count + ")";
    } else {
      choice.reason = "requested " + requested_move + " needs " + std::to_string(SubjectsNeeded(move)) +
                      " subjects, found " + std::to_string(num_subjects) + "; ";
      drawn = true;
    }
  }
  if (drawn) {
    const std::vector<Move> candidates = MovesOfRow(row);
    choice.move = candidates[Draw(rng, candidates.size())];
    choice.reason += count + ": row " + std::to_string(row) + " of table 1 (" + Join(candidates) + "), seed " +
                     std::to_string(seed) + " drew " + std::string(MoveName(choice.move));
  }
  if (SubjectsNeeded(choice.move) >= 2) choice.swap_subjects = Draw(rng, 2) == 1;

  if (requested_effect == "auto") {
    const std::vector<Effect> effects = AutomaticEffects(choice.move);
    choice.effect = effects[Draw(rng, effects.size())];
    if (effects.size() > 1) choice.reason += ", with effect " + std::string(EffectName(choice.effect));
  } else {
    PX_ASSIGN_OR_RETURN(Effect effect, ParseEffect(requested_effect));
    if (EffectSuits(choice.move, effect)) {
      choice.effect = effect;
      if (effect != Effect::kNone) choice.reason += ", with requested effect " + requested_effect;
    } else {
      choice.reason += "; requested effect " + requested_effect + " does not suit " +
                       std::string(MoveName(choice.move)) + ", so none";
    }
  }
  return choice;
}

std::vector<MoveChoice> FallbackMoves(const MoveChoice& first, int num_subjects) {
  std::vector<MoveChoice> fallbacks;
  const int top = std::min(std::clamp(num_subjects, 0, 2), SubjectsNeeded(first.move));
  for (int row = top; row >= 0; --row) {
    for (Move move : MovesOfRow(row)) {
      // With two subjects a subject move is tried on each: a close-up of one may leave the
      // views' field where the other's holds (a subject near the frame's edge).
      const int orders = row >= 1 && num_subjects >= 2 ? 2 : 1;
      for (int order = 0; order < orders; ++order) {
        const bool swap = order == 1 ? !first.swap_subjects : first.swap_subjects;
        if (move == first.move && swap == first.swap_subjects) continue;
        MoveChoice choice;
        choice.move = move;
        choice.effect = Effect::kNone;
        choice.swap_subjects = swap;
        choice.reason =
            "fallback: " + std::string(MoveName(move)) + " (row " + std::to_string(row) + ")" +
            (order == 1 ? (row == 2 ? ", from the second subject to the first" : ", on the second subject") : "");
        fallbacks.push_back(choice);
      }
    }
  }
  return fallbacks;
}

}  // namespace px::direct
