#include "pipeline/envelope/leaning_face.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace boxd::envelope {

namespace {

// The face's rows, bottom to top: each row's cells' mean offset, weighed by their standard
// errors, at the row's mean height, known no better than `row_floor_m`; `flip` reads the face
// from its top down (z from the top).
std::vector<ProfileRow> FaceRows(const std::vector<FaceProfileCell>& cells, double row_m,
                                 double height_m, double row_floor_m, bool flip) {
    struct Sums {
        double w = 0.0, ws = 0.0, wz = 0.0;
    };
    std::map<long, Sums> by_row;
    for (const FaceProfileCell& c : cells) {
        const double z = flip ? height_m - c.z : c.z;
        const double w = 1.0 / std::max(c.se_m * c.se_m, 1e-12);
        Sums& s = by_row[std::lround(std::floor(z / row_m))];
        s.w += w;
        s.ws += w * c.offset_m;
        s.wz += w * z;
    }
    std::vector<ProfileRow> rows;
    for (const auto& [row, s] : by_row)
        rows.push_back({s.ws / s.w, std::max(1.0 / std::sqrt(s.w), row_floor_m), s.wz / s.w});
    return rows;
}

}  // namespace

std::optional<ProfileFoot> LeaningFaceReach(const std::vector<FaceProfileCell>& cells, double row_m,
                                            double height_m, double row_floor_m) {
    for (const bool flip : {false, true}) {
        const std::vector<ProfileRow> rows = FaceRows(cells, row_m, height_m, row_floor_m, flip);
        if (const auto line = OutwardLine(rows)) return FootOfLine(rows, *line);
    }
    return std::nullopt;
}

}  // namespace boxd::envelope
