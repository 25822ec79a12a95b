// A phone photo of a digital oscilloscope's screen (internal to render/;
// PhotoStyle::kDigital): what a lab repeating the experiment today records.
// The display is an LCD of a few hundred pixels a side: a dotted graticule
// filling only part of it, each channel drawn in its own colour as a
// pixelated polyline (a vertical run of pixels per display column), on-screen
// text and markers around the graticule and inside it, and the panel's
// red-green-blue stripes, which the phone resolves or aliases. Around it the
// scope's bezel and body, glare on the glass, the phone's perspective, blur,
// noise and JPEG.
#pragma once

#include "render/oscillograph.h"

namespace impactlab::render {

// Draws the photo (RenderOscillograph's, for the digital style): the truth's
// mapping takes screen divisions to photo pixels exactly, as every style's.
RenderedPhoto RenderDigitalScreen(const OscillographScene& scene, const RenderOptions& options);

}  // namespace impactlab::render
