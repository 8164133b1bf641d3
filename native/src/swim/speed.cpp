#include "kodawari/swim/speed.hpp"

#include <algorithm>

namespace kodawari::swim {

Real bainbridge_speed(Real body_length, Real frequency) {
  return std::max(Real(0), Real(0.25) * body_length * (Real(3) * frequency - Real(4)));
}

Real strouhal_speed(Real frequency, Real peak_to_peak, Real strouhal) {
  if (strouhal <= Real(0)) return Real(0);
  return std::max(Real(0), frequency * peak_to_peak / strouhal);
}

Real swim_speed(SpeedMode mode, Real body_length, Real frequency, Real amplitude, Real strouhal) {
  switch (mode) {
    case SpeedMode::Bainbridge:
      return bainbridge_speed(body_length, frequency);
    case SpeedMode::Strouhal:
      return strouhal_speed(frequency, Real(2) * amplitude * body_length, strouhal);
    case SpeedMode::None:
      break;
  }
  return Real(0);
}

}  // namespace kodawari::swim
