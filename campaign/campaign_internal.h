// What the campaign library's files share (not part of its interface).
#pragma once

#include <string>
#include <vector>

#include "campaign/campaign.h"
#include "pipeline/session_result.h"

namespace impactlab {

// A number of unit kind `kind` ("length", "speed", "inverse_speed",
// "stiffness", "damping", "hertz_stiffness", "pressure", "mass", or "1", "s")
// in system `from`, times this, is in system `to`.
double UnitFactor(const std::string& kind, UnitSystem from, UnitSystem to);

// One session's estimates, in the units `to`.
CampaignSession TabulateSession(const SessionResult& result, const std::string& name,
                                const std::string& file, UnitSystem to);

// The constants each material's sessions share (kMaterialNotGiven has none).
std::vector<MaterialFit> FitMaterials(const std::vector<CampaignSession>& sessions,
                                      double false_alarm);

}  // namespace impactlab
