#ifndef CABLESIM_COUPLE_COUPLE_INTERNAL_H_
#define CABLESIM_COUPLE_COUPLE_INTERNAL_H_

// Inside libcablesim_couple (not installed, C++): what the MoorDyn names
// (moordyn_compat.cc) share with the C interface (cablesim_couple.cc).

#include <string>

#include "couple/cablesim_couple.h"
#include "cablesim/v1/scene.pb.h"

namespace cablesim::couple {

// CableSim_Create from a scene already read (`source`: its file, for
// messages). NULL on error, with CableSim_ErrorMessage set.
CableSimSystem CreateFromProto(const v1::Scene& proto, const std::string& source);
// Sets CableSim_ErrorMessage.
void SetError(const std::string& message);

}  // namespace cablesim::couple

#endif  // CABLESIM_COUPLE_COUPLE_INTERNAL_H_
