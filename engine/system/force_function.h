// The type of the force pass a (contact law, rolling model) pair compiles to: the registry
// (engine/system/law_registry.cpp) makes them, the System calls the one it selected. Kept apart so
// that neither header includes the other.
#pragma once

namespace gravsweep {

struct ForceContext;  // engine/system/force_loop.h
using ForceFunction = void (*)(ForceContext&);

}  // namespace gravsweep
