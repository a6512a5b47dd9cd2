// The paper's taxonomy of 3D pan & scan effects (Table 1, section 3), keyed by the number of
// subjects of interest, and the seeded choice among them (4.1):
//
//   subjects | camera moves                                  | image effects
//   0        | establishing dolly, establishing dolly-out    | (none)
//   1        | dolly in / out, dolly zoom (either direction) | depth-of-field change, saturation/brightness
//   2        | dolly (from one subject to the other)         | focus pull, depth-of-field change
//
// Any move for n subjects also suits a scene with more than n. The automatic choice draws from
// the row of the scene's count (two or more faces: row 2) and never a colour effect (the paper
// leaves those to authoring); a requested move or effect is honoured when the scene allows it.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/status.h"

namespace px::direct {

enum class Move {
  kEstablishingDolly,     // across the valid viewpoints, aimed at the scene centroid, focal f
  kEstablishingDollyOut,  // back along the z axis, aimed at the centroid, focal 1.5f -> f
  kDollyIn,               // from the centroid view (f) in to the subject (1.5f)
  kDollyOut,              // from the subject (1.5f) out to the centroid view (f)
  kDollyZoomOut,          // back along the z axis while zooming in: the subject keeps its size (Vertigo)
  kDollyZoomIn,           // in along the z axis while zooming out: the subject keeps its size
  kDolly,                 // from the first subject to the second, the second ending at the first's size
};

enum class Effect {
  kNone,
  kDofChange,             // aperture from pinhole to the largest valid one, focused on a subject
  kFocusPull,             // the largest valid aperture throughout, focus moving from subject to subject
  kSaturation,            // the subject grows more saturated
  kBrightness,            // the subject brightens
  kDesaturateBackground,  // everything but the subject loses saturation
  kDimBackground,         // everything but the subject dims
};

std::string_view MoveName(Move move);        // "establishing_dolly", ..., "dolly"
std::string_view EffectName(Effect effect);  // "none", "dof_change", ...
StatusOr<Move> ParseMove(std::string_view name);
StatusOr<Effect> ParseEffect(std::string_view name);
const std::vector<Move>& AllMoves();
const std::vector<Effect>& AllEffects();

// The table row a move belongs to: the subjects it needs (0, 1 or 2).
int SubjectsNeeded(Move move);
// Effects that make sense with a move (none always; colour effects need a subject; a focus pull
// needs two).
bool EffectSuits(Move move, Effect effect);
// The effects the automatic choice draws from for a move (paper 4.1: no colour effects).
std::vector<Effect> AutomaticEffects(Move move);

struct MoveChoice {
  Move move = Move::kEstablishingDolly;
  Effect effect = Effect::kNone;
  bool swap_subjects = false;  // two subjects: start at the second (seeded), so either order occurs
  std::string reason;          // which row, what was drawn or requested, and why
};

// The move for a scene with `num_subjects` subjects: `requested_move` "auto" draws from the row
// (capped at 2) with `seed`, "dolly_zoom" draws its direction, a named move is taken when the
// scene has the subjects it needs (otherwise auto, with the reason saying so). `requested_effect`
// "auto" draws from AutomaticEffects, a named effect is taken when it suits the move (otherwise
// none, said in the reason). Deterministic for a given seed. Errors only for unknown names.
StatusOr<MoveChoice> ChooseMove(int num_subjects,
                                const std::string& requested_move,
                                const std::string& requested_effect,
                                uint64_t seed);

// What to try, in order, when `first` cannot be planned (no valid viewpoints for it): the other
// moves of its row, then those of the rows below, each with no effect. Deterministic.
std::vector<MoveChoice> FallbackMoves(const MoveChoice& first, int num_subjects);

}  // namespace px::direct
