// Keeps kodawari_core a real library even before a solver lands, and gives
// the bindings one symbol to check the core and the module were built together.
#include "kodawari/version.hpp"

namespace kodawari {
const char* core_version() { return version(); }
}  // namespace kodawari
