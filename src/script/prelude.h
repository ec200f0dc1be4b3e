// The field objects of VRML97 Annex C and ISO/IEC 19777-1 (SFVec3f, SFRotation, MF arrays, ...)
// and the glue the host calls (docs/scripts.md), as ECMAScript run in each Script's heap first.
#pragma once

namespace vr {
extern const char* const kScriptPrelude;
}
