#!/usr/bin/env python3
"""Would an early stop be right? Renders the accuracy suite's boxes, parcels, tubes and irregular
objects (tests/accuracy/cases.json) at the first N poses of the coverage order of an 18-pose
budget, measures each as the capture would have at that pose (`boxd measure`), and applies the
stop rule of daemon/service/pose_preparer.h: a cuboid, every 95% bound within the target, every
face told flat (quality.face_flatness within 2.5). Prints each session that would stop, whether
its true error lies within its bounds, and a summary per N.

Usage: scripts/early_stop_study.py [--boxd build/daemon/boxd] [--poses 6,9,12,15]
                                   [--target 0.001]
"""
import argparse
import json
import os
import subprocess
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
COVERAGE_18 = [0, 60, 120, 180, 240, 300, 340, 320, 280, 260, 220, 200, 160, 140, 100, 80, 40, 20]
GROUPS = ("box", "parcel", "tube", "irregular", "open flap", "grazing top")
FLAT_FACES = 2.5  # kFlatFaces
KEYS = ("length_m", "width_m", "height_m")


def station_config(case, directory):
    """`boxd measure` options for the config of the station that rendered `case`: how far its
    recorded calibration placed the table's centre, as a station's config says it. The default
    simulated station's is config/sim.yaml; a case with its own calib_center_error_m gets a file
    of its own in `directory`."""
    if "calib_center_error_m" not in case:
        return ["--config", os.path.join(HERE, "..", "config", "sim.yaml")]
    path = os.path.join(directory, "station.yaml")
    with open(path, "w", encoding="utf-8") as f:
        sigma = max(case["calib_center_error_m"], 1e-4)
        f.write(f"measurement:\n  calibration_center_sigma_m: {sigma}\n")
    return ["--config", path]


def errors_mm(result, truth):
    """Each dimension's error against `truth` in mm, rounded to the nanometre: the dimension and
    the truth are written to the hundredth of a millimetre, and their difference in doubles may
    pass an equal bound by 1e-17."""
    return [round(1000 * (result["dimensions"][k] - truth[k]), 6) for k in KEYS]


def synth_args(case, out, angles):
    a = ["synth", "--out", out, "--force", "--dims", *map(str, case["dims"]),
         "--noise", case["noise"], "--frames", str(case["frames"]), "--seed", str(case["seed"]),
         "--angles", ",".join(map(str, angles))]
    for key, flag in (("yaw", "--yaw"), ("distance", "--distance"), ("elevation", "--elevation"),
                      ("aim_height", "--aim-height"),
                      ("calib_center_error_m", "--calib-center-error-m"),
                      ("calib_axis_error_deg", "--calib-axis-error-deg")):
        if key in case:
            a += [flag, str(case[key])]
    if "offset" in case:
        a += ["--offset", *map(str, case["offset"])]
    extra = case.get("synth", [])
    i = 0
    while i < len(extra):  # the case's own angles give way to the coverage order's
        if extra[i] == "--angles":
            i += 2
            continue
        a.append(extra[i])
        i += 1
    return a


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--boxd", default=os.path.join(HERE, "..", "build", "daemon", "boxd"))
    p.add_argument("--poses", default="6,9,12,15")
    p.add_argument("--target", type=float, default=0.001)
    args = p.parse_args()
    with open(os.path.join(HERE, "..", "tests", "accuracy", "cases.json")) as f:
        cases = [c for c in json.load(f)["cases"] if c.get("group", "box") in GROUPS]
    with tempfile.TemporaryDirectory() as tmp:
        for n in map(int, args.poses.split(",")):
            stops = misses = 0
            worst = 0.0
            print(f"== the first {n} poses: {COVERAGE_18[:n]}")
            for case in cases:
                out = os.path.join(tmp, case["name"])
                subprocess.run([args.boxd, *synth_args(case, out, COVERAGE_18[:n])],
                               capture_output=True, check=True)
                r = json.loads(subprocess.run([args.boxd, "measure", "--session", out,
                                               *station_config(case, tmp)],
                                              capture_output=True, text=True).stdout)
                if r["status"] != "ok":
                    continue
                with open(os.path.join(out, "session.json")) as f:
                    truth = json.load(f)["ground_truth"]
                err = [r["dimensions"][k] - truth[k] for k in KEYS]
                bound = [r["uncertainty_m"][k] for k in KEYS]
                flat = r["quality"].get("face_flatness")
                if not (r["shape"] == "cuboid" and max(bound) <= args.target and
                        flat is not None and flat <= FLAT_FACES):
                    continue
                stops += 1
                missed = any(abs(e) > b for e, b in zip(err, bound))
                misses += missed
                worst = max(worst, *map(abs, err))
                print("  stops: %-22s %-10s error %6.2f %6.2f %6.2f mm, bound %5.2f %5.2f %5.2f mm, "
                      "flatness %.2f%s" % (case["name"], case.get("group", "box"),
                                           *(e * 1e3 for e in err), *(b * 1e3 for b in bound),
                                           flat, "  (outside its bound)" if missed else ""))
            print(f"   {stops} of {len(cases)} sessions stop; {misses} with an error outside its "
                  f"bound; worst error of those that stop {worst * 1e3:.2f} mm")


if __name__ == "__main__":
    main()
