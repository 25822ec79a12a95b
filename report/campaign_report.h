// A campaign's report (campaign/campaign.h): the sessions' estimates grouped
// by material and geometry, the constants each material shares with the
// Birge ratio and the sessions' pulls, the inputs that could not be read; and
// the figures: restitution against impact speed, contact time against speed
// with each session's fitted law, the constants per session with error bars.
// Formatting only: everything shown is read from the campaign.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "campaign/campaign.h"
#include "report/svg_plot.h"
#include "report/tables.h"

namespace impactlab {

std::vector<Table> BuildCampaignTables(const Campaign& campaign);
std::vector<Plot> CampaignFigures(const Campaign& campaign);

// One self-contained page: the tables, then the figures as inline SVG.
std::string RenderCampaignHtml(const Campaign& campaign);

// The figures as SVG files: (file name, SVG text), in the page's order.
std::vector<std::pair<std::string, std::string>> RenderCampaignFigures(const Campaign& campaign);

}  // namespace impactlab
