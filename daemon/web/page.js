"use strict";
// The operator page's logic: polls /v1/status, shows a live panel while a parcel is measured
// (the result below then is the previous parcel's: dimmed and labelled), the result of the latest
// or of a measurement opened from the history, and the calibration in force. Every time on the
// page is the browser's local time, in one format, said once in the header.
const $ = (id) => document.getElementById(id);
const token = $("token");
token.value = localStorage.getItem("boxd-token") || "";
token.addEventListener("change", () => localStorage.setItem("boxd-token", token.value));

// Calls the API; returns the parsed JSON (or the bytes), throws {code, message} on an error.
async function api(path, options = {}) {
  const headers = {};
  if (token.value) headers["Authorization"] = "Bearer " + token.value;
  if (options.body) headers["Content-Type"] = "application/json";
  const res = await fetch(path, { ...options, headers });
  const json = (res.headers.get("Content-Type") || "").includes("json");
  const body = json ? await res.json() : await res.arrayBuffer();
  if (!res.ok) {
    const e = (json && body.error) || { code: String(res.status), message: res.statusText };
    throw Object.assign(new Error(e.message), { code: e.code, status: res.status });
  }
  return body;
}

const mm = (m) => (m * 1000).toFixed(1);
const ago = (s) => s < 120 ? `${s} s ago` : s < 7200 ? `${Math.round(s / 60)} min ago`
  : s < 172800 ? `${Math.round(s / 3600)} h ago` : `${Math.round(s / 86400)} days ago`;
const timeFormat = new Intl.DateTimeFormat(undefined, { year: "numeric", month: "2-digit",
  day: "2-digit", hour: "2-digit", minute: "2-digit", second: "2-digit" });
const localTime = (utc) => utc ? timeFormat.format(new Date(utc)) : "";
function text(el, value) { el.textContent = value; return el; }
function row(table, cells, tag = "td") {
  const tr = table.insertRow();
  for (const [value, cls] of cells) {
    const td = document.createElement(tag);
    if (cls) td.className = cls;
    tr.appendChild(text(td, value));
  }
  return tr;
}
function say(message, error = false) { text($("message"), message).className = error ? "error" : ""; }
function offsetNote() {
  const minutes = -new Date().getTimezoneOffset(), sign = minutes < 0 ? "-" : "+";
  const hh = String(Math.floor(Math.abs(minutes) / 60)).padStart(2, "0");
  return `times are local (UTC${sign}${hh}:${String(Math.abs(minutes) % 60).padStart(2, "0")})`;
}

let latestId;           // the last finished measurement (status.last_measurement_id)
let openedId = null;    // a measurement opened from the history, or null: the latest is shown
let shownId;            // the measurement in the result panel
let startedParcel = {}; // parcel ids of the measurements this page started, by id

// The live panel while a parcel is measured; the result below is then the previous parcel's.
function showLive(s) {
  const running = s.state === "measuring" && s.progress;
  $("live").hidden = !running;
  $("last").classList.toggle("previous", !!running && !openedId);
  $("previous-note").hidden = !running || !!openedId;
  if (!running) return;
  const p = s.progress, parcel = startedParcel[s.measurement_id];
  text($("live-id"), s.measurement_id || "");
  text($("live-parcel"), parcel ? `parcel ${parcel}` : "");
  $("live-bar").style.width = `${Math.round(100 * p.pose / Math.max(1, p.poses))}%`;
  text($("live-text"), p.stage === "processing"
    ? `Computing the size from ${p.pose} poses…`
    : `${p.pose} poses captured. The table stops as soon as the size is determined (at most ${p.poses} poses).`);
  text($("previous-note"), shownId
    ? `Below: the previous parcel (${shownId}), not the one on the table.` : "");
}

// The audit trail of GET /v1/status: the event counter, the software, the records' check.
function showAudit(a) {
  const facts = $("audit-facts");
  facts.replaceChildren();
  if (!a) return;
  const fact = (name, value) => {
    facts.append(text(document.createElement("dt"), name), text(document.createElement("dd"), value));
  };
  const e = a.last_event;
  fact("Event counter", e ? `${a.event_counter} (last: ${e.what}, ${localTime(e.at)}, ${e.via})`
                          : `${a.event_counter}`);
  fact("Software", `${a.software.version}, commit ${a.software.commit}, SHA-256 ${a.software.sha256.slice(0, 16)}…`);
  const r = a.records;
  fact("Stored records", r.intact ? `${r.checked} intact (checked at start)` : `CHANGED: ${r.problem}`);
}

async function refreshStatus() {
  try {
    const s = await api("/v1/status");
    text($("state"), s.state).className = "state " + s.state;
    text($("state-detail"), s.state === "error" && s.last_error
      ? `${s.last_error.code}: ${s.last_error.message}` : "");
    $("measure").disabled = s.state === "measuring" || s.state === "calibrating";
    showAudit(s.audit);
    $("zero-scale").hidden = !s.devices.scale;
    $("zero-scale").disabled = s.state === "measuring" || s.state === "calibrating";
    showLive(s);
    if (s.last_measurement_id !== latestId) {
      latestId = s.last_measurement_id;
      await Promise.all([openedId ? null : openMeasurement(null), refreshHistory()]);
    }
  } catch (e) {
    text($("state"), e.status === 401 ? "token needed" : "unreachable").className = "state error";
  }
}

// Shows measurement `id` (null: the latest) in the result panel, with its 3-D view.
// The station's billing block (its config's billing: section), or nothing without one.
function showBilling(b) {
  const table = $("billing");
  table.replaceChildren();
  table.hidden = !b;
  if (!b) return;
  const u = b.units;
  row(table, [["Billing", "wide"], [b.billable ? "billable" : "not billable", "value"],
              [b.billable ? `${b.rounding}, ${b.length.division} ${u.length} divisions` : b.reason]]);
  for (const name of ["length", "width", "height"]) {
    const d = b[name];
    row(table, [[name], [d.divisions != null ? `${d.value} ${u.length}` : "—", "value"],
                [d.divisions != null ? `${d.divisions} × ${d.division} ${u.length}` : d.why_not]]);
  }
  if (b.volume != null) row(table, [["volume"], [`${b.volume} ${u.volume}`, "value"], [""]]);
  if (b.actual_weight != null) row(table, [["weighed"], [`${b.actual_weight} ${u.weight}`, "value"], [""]]);
  for (const c of b.carriers) {
    const billed = c.billable_weight != null ? `bills ${c.billable_weight} ${u.weight}` : "not weighed";
    row(table, [[c.carrier], [`${c.dimensional_weight} ${u.weight}`, "value"],
                [`dimensional at ${c.divisor} ${u.volume}/${u.weight}; ${billed}`]]);
  }
}

async function openMeasurement(id) {
  let m;
  try {
    m = await api(`/v1/measurements/${id || "last"}`);
  } catch (e) {
    text($("last-note"), e.status === 404 && !id ? "No measurement yet." : `${e.code}: ${e.message}`);
    return;
  }
  openedId = id;
  shownId = m.id;
  text($("last-label"), id ? "Measurement" : "Last measurement");
  $("back-to-latest").hidden = !id;
  text($("last-id"), m.id);
  text($("last-parcel"), m.parcel_id ? `parcel ${m.parcel_id}` : "");
  const dims = $("dims");
  dims.replaceChildren();
  const when = `finished ${localTime(m.finished_at)}`;
  if (m.dimensions) {
    const d = m.dimensions, u = m.uncertainty_m;
    for (const [name, key] of [["Length", "length_m"], ["Width", "width_m"], ["Height", "height_m"]]) {
      row(dims, [[name], [`${mm(d[key])} mm`, "value"], [u ? `± ${mm(u[key])} mm` : ""]]);
    }
    row(dims, [["Volume"], [`${(d.volume_m3 * 1000).toFixed(2)} L`, "value"], [""]]);
    row(dims, [["Shape"], [m.shape || ""], [""]]);
    const w = m.weight;
    if (w) {
      row(dims, [["Weight"], [w.value != null ? `${w.value} ${w.unit}` : "—", "value"],
                 [w.value != null ? `e = ${w.division} ${w.unit}` : w.why_not]]);
    }
    text($("last-note"), `${m.status}, ${m.quality.poses} poses, ${when}`);
    showBilling(m.billing);
  } else {
    text($("last-note"), `${m.status}: ${m.reason.code}: ${m.reason.message} (${when})`);
    showBilling(null);
  }
  for (const tr of $("history-table").rows) tr.classList.toggle("shown", tr.dataset.id === m.id);
  try {
    showCloud($("view"), m, await api(`/v1/measurements/${m.id}/cloud.ply`));
  } catch (e) {
    text($("view"), m.status === "ok" ? `3-D view unavailable: ${e.message}` : "No cloud.");
  }
}

async function refreshHistory() {
  const table = $("history-table");
  try {
    const list = (await api("/v1/measurements?limit=20")).measurements;
    table.replaceChildren();
    row(table, [["id", "wide"], ["finished"], ["parcel"], ["status"], ["L × W × H mm"],
                ["shape", "wide"]], "th");
    for (const m of list) {
      const d = m.dimensions;
      const tr = row(table, [[m.id, "wide"], [localTime(m.finished_at)], [m.parcel_id || ""],
        [m.status, "status"],
        [d ? `${mm(d.length_m)} × ${mm(d.width_m)} × ${mm(d.height_m)}` : (m.reason ? m.reason.code : "")],
        [m.shape || "", "wide"]]);
      tr.className = m.status + (m.id === shownId ? " shown" : "");
      tr.dataset.id = m.id;
      tr.addEventListener("click", () => { location.hash = m.id; });
    }
  } catch (e) { text(table, `${e.code}: ${e.message}`); }
}

async function refreshCalibration() {
  const facts = $("calibration-facts");
  const fact = (name, value) => {
    facts.append(text(document.createElement("dt"), name), text(document.createElement("dd"), value));
  };
  try {
    const c = await api("/v1/calibration");
    facts.replaceChildren();
    if (!c.calibrated) {
      fact("Status", "not calibrated: calibrate with a reference box (POST /v1/calibrate)");
      return;
    }
    fact("Made", c.calibrated_at ? `${localTime(c.calibrated_at)} (${ago(c.age_s)})`
                                 : "with the station config (its date is not recorded)");
    if (c.run && c.run.reference_m) {
      fact("Reference box", c.run.reference_m.map(mm).join(" × ") + " mm");
      const q = c.run.quality || {};
      if (q.face_rms_m != null) {
        fact("Fit", `faces ${mm(q.face_rms_m)} mm RMS, table ${mm(q.table_rms_m)} mm RMS, ${q.poses_used} poses`);
      }
    }
    fact("Depth offset", `${mm(c.depth_offset_m)} mm`);
    fact("Focal scale", c.focal_scale.toFixed(4));
  } catch (e) { facts.replaceChildren(text(document.createElement("dd"), `${e.code}: ${e.message}`)); }
}

$("measure").addEventListener("click", async () => {
  const parcel = $("parcel").value.trim();
  try {
    const started = await api("/v1/measure", { method: "POST",
      body: JSON.stringify(parcel ? { parcel_id: parcel } : {}) });
    if (parcel) startedParcel[started.id] = parcel;
    say(`${started.id} started${parcel ? " for parcel " + parcel : ""}`);
    $("parcel").value = "";
    if (openedId) location.hash = "";  // back to the latest: the new result will be shown
  } catch (e) { say(`${e.code}: ${e.message}`, true); }
  refreshStatus();
});
$("zero-scale").addEventListener("click", async () => {
  try {
    const r = await api("/v1/scale/zero", { method: "POST" });
    say(`scale zeroed (${r.scale})`);
  } catch (e) { say(`${e.code}: ${e.message}`, true); }
});
$("parcel").addEventListener("keydown", (e) => { if (e.key === "Enter") $("measure").click(); });
$("back-to-latest").addEventListener("click", () => { location.hash = ""; });
// The opened measurement is in the address (#m-000042): a link to it, and Back returns.
window.addEventListener("hashchange", () => openMeasurement(location.hash.slice(1) || null));

text($("clock-note"), offsetNote());
openedId = location.hash.slice(1) || null;
if (openedId) openMeasurement(openedId);
refreshStatus();
refreshCalibration();
setInterval(refreshStatus, 500);
setInterval(refreshCalibration, 30000);
