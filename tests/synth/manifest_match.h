// Checks, field by field and to the last bit, that the session the manifest
// reader (io/manifest.h) returned holds what a generator planned to write
// (synth/manifest_writer.h).
#pragma once

#include "io/session.h"
#include "synth/manifest_writer.h"

namespace impactlab::testing {

void CheckReadsBack(const SessionManifest& planned, const Session& read);

}  // namespace impactlab::testing
