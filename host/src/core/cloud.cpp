// The range check every cloud passes before it is gridded (groovetrace/cloud.hpp).

#include <algorithm>
#include <cmath>
#include <groovetrace/cloud.hpp>
#include <groovetrace/error.hpp>
#include <sstream>
#include <string>

namespace groovetrace {

void require_in_range(const Cloud& cloud) {
  std::size_t beyond = 0, first = 0;
  double value = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!beyond_max_coordinate(cloud.x[i], cloud.y[i], cloud.z[i])) continue;
    if (beyond++ == 0) {
      first = i;
      value = std::max({std::abs(cloud.x[i]), std::abs(cloud.y[i]), std::abs(cloud.z[i])});
    }
  }
  if (beyond == 0) return;
  std::ostringstream msg;
  msg << beyond << (beyond == 1 ? " point lies" : " points lie") << " beyond " << kMaxCoordinate
      << " m of the frame's origin (the first, point " << first << ", at " << value
      << " m): a corrupt scan or a wrong unit (--units)";
  throw InputError(msg.str());
}

}  // namespace groovetrace
