// Analysis functions (filled in by the analysis stage).
#include "bindings.hpp"

namespace bvc3d::py {

void bind_analysis(pyb::module_& m) { (void)m; }

}  // namespace bvc3d::py
