#include "daemon/service/measurement_csv.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

namespace boxd {

namespace {

using nlohmann::json;

// One CSV field: quoted when it holds a comma, a quote or a line break (quotes doubled).
std::string Field(const std::string& text) {
    if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
    std::string out = "\"";
    for (char c : text) {
        if (c == '"') out += '"';
        out += c;
    }
    return out + "\"";
}

// Text someone typed: defused when a spreadsheet would take it for a formula.
std::string Typed(const json& v) {
    if (!v.is_string()) return "";
    std::string s = v.get<std::string>();
    if (!s.empty() && std::string("=+-@\t\r").find(s[0]) != std::string::npos) s = "'" + s;
    return s;
}

std::string Number(const json& v, double scale = 1.0, int decimals = 4) {
    if (!v.is_number()) return "";
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.*f", decimals, v.get<double>() * scale);
    return buf;
}

std::string Text(const json& v) { return v.is_string() ? v.get<std::string>() : ""; }
std::string Bool(const json& v) { return v.is_boolean() ? (v.get<bool>() ? "true" : "false") : ""; }

const json& At(const json& j, const char* key) {
    static const json kNull;
    return j.is_object() && j.contains(key) ? j[key] : kNull;
}

// The carriers named in any record's billing, in order of first appearance.
std::vector<std::string> Carriers(const std::vector<json>& records) {
    std::vector<std::string> names;
    for (const json& r : records) {
        for (const json& c : At(At(r, "billing"), "carriers")) {
            const std::string name = Text(At(c, "carrier"));
            if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
        }
    }
    return names;
}

std::vector<std::string> Row(const json& r, const std::vector<std::string>& carriers) {
    const json& d = At(r, "dimensions");
    const json& u = At(r, "uncertainty_m");
    const json& w = At(r, "weight");
    const json& b = At(r, "billing");
    std::vector<std::string> row = {Text(At(r, "id")),
                                    Text(At(r, "finished_at")),
                                    Typed(At(r, "parcel_id")),
                                    Text(At(r, "status")),
                                    Text(At(At(r, "reason"), "code")),
                                    Typed(At(At(r, "reason"), "message")),
                                    Number(At(d, "length_m"), 1e3, 2),
                                    Number(At(d, "width_m"), 1e3, 2),
                                    Number(At(d, "height_m"), 1e3, 2),
                                    Number(At(u, "length_m"), 1e3, 2),
                                    Number(At(u, "width_m"), 1e3, 2),
                                    Number(At(u, "height_m"), 1e3, 2),
                                    Text(At(r, "shape")),
                                    Number(At(w, "value")),
                                    Text(At(w, "unit")),
                                    Bool(At(b, "billable")),
                                    Typed(At(b, "reason")),
                                    Text(At(At(b, "units"), "length")),
                                    Number(At(At(b, "length"), "value")),
                                    Number(At(At(b, "width"), "value")),
                                    Number(At(At(b, "height"), "value")),
                                    Text(At(At(b, "units"), "volume")),
                                    Number(At(b, "volume")),
                                    Text(At(At(b, "units"), "weight")),
                                    Number(At(b, "actual_weight"))};
    for (const std::string& name : carriers) {
        json found;
        for (const json& c : At(b, "carriers")) {
            if (Text(At(c, "carrier")) == name) found = c;
        }
        row.push_back(Number(At(found, "dimensional_weight")));
        row.push_back(Number(At(found, "billable_weight")));
    }
    return row;
}

void AppendLine(std::string& out, const std::vector<std::string>& fields) {
    for (std::size_t i = 0; i < fields.size(); ++i) {
        if (i) out += ',';
        out += Field(fields[i]);
    }
    out += "\r\n";  // RFC 4180's line break
}

}  // namespace

std::string MeasurementsCsv(const std::vector<json>& records) {
    const std::vector<std::string> carriers = Carriers(records);
    std::vector<std::string> header = {"id",
                                       "finished_at",
                                       "parcel_id",
                                       "status",
                                       "reason_code",
                                       "reason",
                                       "length_mm",
                                       "width_mm",
                                       "height_mm",
                                       "length_bound_mm",
                                       "width_bound_mm",
                                       "height_bound_mm",
                                       "shape",
                                       "weight",
                                       "weight_unit",
                                       "billable",
                                       "billing_reason",
                                       "billed_length_unit",
                                       "billed_length",
                                       "billed_width",
                                       "billed_height",
                                       "billed_volume_unit",
                                       "billed_volume",
                                       "billed_weight_unit",
                                       "actual_weight"};
    for (const std::string& name : carriers) {
        header.push_back(name + "_dimensional_weight");
        header.push_back(name + "_billable_weight");
    }
    std::string out;
    AppendLine(out, header);
    for (const json& r : records) AppendLine(out, Row(r, carriers));
    return out;
}

Result<std::string> CheckSince(const std::string& since) {
    // YYYY-MM-DD, then optionally THH:MM, :SS, .s to .sss, and a closing Z.
    const std::string form = "dddd-dd-ddTdd:dd:dd.ddd";
    std::string t = since;
    if (t.size() > 10 && t.back() == 'Z') t.pop_back();
    std::size_t i = 0;
    for (; i < t.size() && i < form.size(); ++i) {
        const bool digit = std::isdigit(static_cast<unsigned char>(t[i])) != 0;
        if (form[i] == 'd' ? !digit : t[i] != form[i]) break;
    }
    const bool whole = i == t.size() && (i == 10 || i == 16 || i == 19 || i >= 21);
    if (!whole) {
        return Error{ErrorCode::kInvalidInput,
                     "since must be a UTC date or time such as 2026-12-05 or "
                     "2026-12-05T10:00:00Z, got '" +
                         since + "'"};
    }
    // Without the Z, it compares with the stored "2026-12-05T10:00:00.000Z" as text.
    return t;
}

}  // namespace boxd
