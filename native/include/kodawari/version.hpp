#pragma once

namespace kodawari {
#ifdef KODAWARI_VERSION
inline const char* version() { return KODAWARI_VERSION; }
#else
inline const char* version() { return "0.0.0"; }
#endif
}  // namespace kodawari
