#include "pipeline/fit/face_choice.h"

#include <algorithm>

namespace boxd {

bool ReadingRays::Covers(std::size_t readings) const {
    if (!view || !cameras || view->size() != readings) return false;
    return std::all_of(view->begin(), view->end(),
                       [&](std::uint16_t v) { return v < cameras->size(); });
}

}  // namespace boxd
