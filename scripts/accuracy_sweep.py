#!/usr/bin/env python3
"""Ideal boxes on stations nobody chose: renders COUNT boxes of random size (0.12-0.6 m long,
0.06-0.5 m tall), on random stations (camera 0.8-1.15 m away, 30-50 degrees up, aimed at 30-60%
of the box's height), with either noise model or none, 1-6 frames, 8-36 poses, the box up to
5 cm off the axis at any yaw, and the synthetic station's default turntable angle and
calibration errors, then measures each with `boxd measure`. The draws come from SEED only, so a
sweep is repeatable; the accuracy suite (tests/accuracy/cases.json) is chosen by hand, this is
not.

Prints each case (errors and 95% bounds in mm, or the refusal) and a summary: the worst and RMS
error per dimension, how many footprint errors exceed 1 mm, how many dimensions lie within
their reported bound, and the median bound against the median error.

With --objects parcels it draws real parcels instead, each of a kind drawn evenly: a carton
bulging 2-6 mm (its top up to 4 mm), strapped (1-3 mm bands), labelled (0.5-2 mm), with rounded
edges (5-20 mm), a tube standing or lying, a bag, an L-shaped pack, or a carton with a flap
open 20-90 degrees; 12-24 poses of 2-4 frames, Kinect or RealSense noise; and the summary adds
each kind's worst error and how many of its dimensions lie within their bounds.

With --objects few it draws cartons seen from 1-5 poses, evenly or unevenly spaced (the issue's
few-poses promise: within 5 mm, or refused with its reason); with --objects pairs, two cartons
2-8 cm apart, which must all be refused MULTIPLE_OBJECTS.

With --objects shapes it draws shapes nobody tuned to, of a kind drawn evenly: prisms and
wedges lying on a face, frusta (cartons tapering 5-40 mm a side), pyramids, bags, lying tubes,
sacks bulging low, lying bottles, cartons on chamfered bases (5-40 mm), a small carton standing on
a larger one and cartons with a strap looped above the top, on stations drawn as for the parcels
but with a time-of-flight camera too (its station's surfaces reflecting 5-60%); each kind is
reported per sensor, then each shape over the sensors and each sensor over the shapes, with
how many of the objects wholly in view (not refused OBJECT_TOO_LARGE) were refused. For every
mode the summary counts confident wrong numbers: a dimension whose true error is larger than
twice its reported 95% bound plus 1 mm.

With --effects each object also gets one effect of real cameras drawn evenly (a dark foot,
a projector's or second imager's shadows, fattened edges, correlated noise, a fixed pattern, or
none), and the summary adds each effect's line.

With --one-pose each object is seen from one pose only (the cuboid assumption: within 5 mm and
its bounds, or refused).

With --objects small it draws small and flat cartons: 60-300 mm long, 32-80 mm high (above
the 30 mm `refusal.min_dimension_m`), on stations drawn as for the parcels (the camera 0.8-1.05 m
away), 12-24 poses of 2-5 frames; the summary says which are flat (at most half as high as
wide).

Usage: scripts/accuracy_sweep.py [--boxd build/daemon/boxd]
                                 [--objects boxes|parcels|small|few|pairs|shapes]
                                 [--seed 1] [--count 60] [--jobs 2] [--one-pose] [--effects]
Exit status 1 when a measured object is off by more than --fail-above-mm (default 1.0 for
boxes, 3.0 for parcels, 2.0 for small cartons, 5.0 for few poses and one pose) in any dimension, or no case
could be measured, or one is refused NO_OBJECT; for pairs, when any pair is measured or refused with another code;
for shapes, when any number is confidently wrong.
"""
import argparse
import concurrent.futures
import json
import math
import os
import random
import statistics
import subprocess
import sys
import tempfile

from early_stop_study import HERE, KEYS, errors_mm, station_config

DISC_RADIUS_M = 0.4  # the synthetic turntable's disc


def draw_case(rng, index, seed):
    """One station and box, drawn so that the box stands on the disc."""
    while True:
        length = rng.uniform(0.12, 0.6)
        width = rng.uniform(0.1, length)
        height = rng.uniform(0.06, 0.5)
        offset = (rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05))
        reach = math.hypot(length, width) / 2 + math.hypot(*offset)
        if reach < DISC_RADIUS_M - 0.01:
            break
    return {
        "name": f"s{seed}_{index}",
        "args": ["--dims", f"{length:.3f}", f"{width:.3f}", f"{height:.3f}",
                 "--noise", rng.choice(["kinect", "kinect", "realsense", "none"]),
                 "--poses", str(rng.choice([8, 12, 18, 18, 24, 36])),
                 "--frames", str(rng.choice([1, 2, 3, 4, 6])),
                 "--seed", str(1000 * seed + index),
                 "--distance", f"{rng.uniform(0.8, 1.15):.2f}",
                 "--elevation", f"{rng.uniform(30, 50):.0f}",
                 "--aim-height", f"{height * rng.uniform(0.3, 0.6):.3f}",
                 "--offset", f"{offset[0]:.3f}", f"{offset[1]:.3f}",
                 "--yaw", f"{rng.uniform(-45, 45):.0f}"],
    }


def parcel_station(rng, dims, render_seed, frames, distance, sensors=("kinect", "realsense")):
    """`boxd synth` options for an object of `dims` on a station drawn for the parcel sweeps:
    one of `sensors` (a time-of-flight one's surfaces reflecting 5-60%), 12-24 poses of a count
    of `frames`, the camera `distance` (a range) away and 30-50 degrees up, the object up to 3 cm
    off the axis at any yaw."""
    length, width, height = dims
    noise = rng.choice(list(sensors))
    # A time-of-flight station's surfaces reflect from a black mat's 5% to a light top's 60%.
    albedo = ["--multipath-albedo", f"{rng.uniform(0.05, 0.6):.2f}"] if noise == "tof" else []
    return ["--dims", f"{length:.3f}", f"{width:.3f}", f"{height:.3f}",
            "--noise", noise, *albedo,
            "--poses", str(rng.choice([12, 18, 24])),
            "--frames", str(rng.choice(frames)),
            "--seed", str(render_seed),
            "--distance", f"{rng.uniform(*distance):.2f}",
            "--elevation", f"{rng.uniform(30, 50):.0f}",
            "--aim-height", f"{height * rng.uniform(0.3, 0.6):.3f}",
            "--offset", f"{rng.uniform(-0.03, 0.03):.3f}", f"{rng.uniform(-0.03, 0.03):.3f}",
            "--yaw", f"{rng.uniform(0, 90):.0f}"]


PARCEL_KINDS = ("bulge", "strap", "label", "rounded", "tube", "lying tube", "bag", "l_shape",
                "flap")


def draw_parcel(rng, index, seed):
    """One real parcel of a kind drawn evenly, on a station drawn as for the boxes."""
    kind = PARCEL_KINDS[rng.randrange(len(PARCEL_KINDS))]
    length = rng.uniform(0.2, 0.5)
    width = rng.uniform(0.15, length)
    height = rng.uniform(0.1, 0.4)
    features = {
        "bulge": lambda: ["--bulge", f"{rng.uniform(0.002, 0.006):.4f}",
                          "--bulge-top", f"{rng.uniform(0.0, 0.004):.4f}"],
        "strap": lambda: ["--strap", f"{rng.uniform(0.001, 0.003):.4f}"],
        "label": lambda: ["--label", f"{rng.uniform(0.0005, 0.002):.4f}"],
        "rounded": lambda: ["--edge-radius", f"{rng.uniform(0.005, 0.02):.3f}"],
        "tube": lambda: ["--shape", "cylinder"],
        "lying tube": lambda: ["--shape", "lying_cylinder"],
        "bag": lambda: ["--shape", "bag"],
        "l_shape": lambda: ["--shape", "l_shape"],
        "flap": lambda: ["--flap-deg", f"{rng.uniform(20, 90):.0f}"],
    }[kind]()
    if kind == "tube":
        length = width = rng.uniform(0.1, 0.25)
    elif kind == "lying tube":
        width = height = rng.uniform(0.08, 0.2)
    return {
        "name": f"p{seed}_{index}",
        "kind": kind,
        "args": [*parcel_station(rng, (length, width, height), 1000 * seed + index, [2, 3, 4],
                                 (0.85, 1.15)), *features],
    }


SHAPE_KINDS = ("prism", "wedge", "frustum", "pyramid", "bag", "lying tube", "sack", "lying bottle",
               "chamfered", "box on box", "handle")


def draw_shape(rng, index, seed):
    """One shape of a kind drawn evenly, its station drawn as for the parcels; its kind names
    the sensor too."""
    kind = SHAPE_KINDS[rng.randrange(len(SHAPE_KINDS))]
    length = rng.uniform(0.15, 0.5)
    width = rng.uniform(0.1, length)
    height = rng.uniform(0.06, 0.35)
    shape = {"lying tube": "lying_cylinder", "lying bottle": "lying_bottle",
             "box on box": "box_on_box"}.get(kind, kind)
    features = ["--shape", shape]
    if kind == "frustum":
        features += ["--taper-m", f"{rng.uniform(0.005, min(0.04, 0.3 * width)):.3f}"]
    elif kind == "chamfered":
        features += ["--taper-m", f"{rng.uniform(0.005, min(0.04, width / 4, height / 2)):.3f}"]
    elif kind in ("lying tube", "lying bottle"):
        width = height = rng.uniform(0.06, 0.2)
    station = parcel_station(rng, (length, width, height), 1000 * seed + index, [2, 3, 4],
                             (0.85, 1.15), ("kinect", "realsense", "tof"))
    noise = station[station.index("--noise") + 1]
    return {"name": f"h{seed}_{index}", "kind": f"{kind} {noise}", "args": [*station, *features]}


EFFECTS = ("none", "dark foot", "shadow", "fattening", "correlated", "fixed pattern")


def draw_effect(rng, case):
    """Adds one effect of real cameras, drawn evenly (docs/measuring.md, sensor effects), to `case`:
    a base reading no depth 10-40 mm up, the shadows of a projector (Kinect, 75 mm either side)
    or a second imager (RealSense, 50 mm to the right), edges fattened 1-4 pixels, correlated
    noise of 0.5-2 mm, or a fixed pattern of 0.5-3 mm (both at 1 m)."""
    effect = EFFECTS[rng.randrange(len(EFFECTS))]
    kinect = case["args"][case["args"].index("--noise") + 1] == "kinect"
    case["args"] += {
        "none": lambda: [],
        "dark foot": lambda: ["--dark-band", "0", f"{rng.uniform(0.01, 0.04):.3f}"],
        "shadow": lambda: ["--shadow-baseline-m",
                           f"{rng.choice([-0.075, 0.075]) if kinect else 0.05:.3f}"],
        "fattening": lambda: ["--edge-fattening-px", str(rng.randint(1, 4))],
        "correlated": lambda: ["--correlated-noise-m", f"{rng.uniform(0.0005, 0.002):.4f}"],
        "fixed pattern": lambda: ["--fixed-pattern-m", f"{rng.uniform(0.0005, 0.003):.4f}"],
    }[effect]()
    case["effect"] = effect
    return case


def confidently_wrong(error_mm, bound_mm):
    """A number a carrier would bill by that is wrong by more than its bound says it could be."""
    return abs(error_mm) > 2.0 * bound_mm + 1.0


def draw_small(rng, index, seed):
    """One small or flat carton, on a station drawn as for the parcels but nearer."""
    length = rng.uniform(0.06, 0.3)
    width = rng.uniform(max(0.05, 0.4 * length), length)
    height = rng.uniform(0.032, 0.08)
    return {
        "name": f"m{seed}_{index}",
        "kind": "flat" if height <= 0.5 * width else "small",
        "args": parcel_station(rng, (length, width, height), 1000 * seed + index, [2, 3, 4, 5],
                               (0.8, 1.05)),
    }


def draw_few(rng, index, seed):
    """One carton seen from few poses: 1-5, evenly or unevenly spaced over the turn."""
    length = rng.uniform(0.15, 0.5)
    width = rng.uniform(0.12, length)
    height = rng.uniform(0.08, 0.4)
    count = rng.choice([1, 2, 3, 3, 4, 5])
    if rng.random() < 0.5:
        start = rng.uniform(0, 360)
        angles = [(start + 360.0 * i / count) % 360 for i in range(count)]
    else:
        angles = [rng.uniform(0, 360) for _ in range(count)]
    return {
        "name": f"f{seed}_{index}",
        "kind": f"{count} pose{'s' if count > 1 else ''}",
        "args": [*parcel_station(rng, (length, width, height), 1000 * seed + index, [2, 3, 4],
                                 (0.85, 1.15)),
                 "--angles", ",".join(f"{a:.0f}" for a in sorted(angles))],
    }


def draw_pair(rng, index, seed):
    """Two cartons side by side, 2-8 cm apart, each wholly on the disc: no single size is
    right, and the answer expected is MULTIPLE_OBJECTS."""
    while True:
        first = [rng.uniform(0.12, 0.3), rng.uniform(0.1, 0.25), rng.uniform(0.08, 0.35)]
        second = [rng.uniform(0.08, 0.25), rng.uniform(0.06, 0.2), rng.uniform(0.04, 0.35)]
        gap = rng.uniform(0.02, 0.08)
        y = (rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05))
        x = (-(first[0] + gap) / 2, (second[0] + gap) / 2)
        reach = max(math.hypot(x[0], y[0]) + math.hypot(first[0], first[1]) / 2,
                    math.hypot(x[1], y[1]) + math.hypot(second[0], second[1]) / 2)
        if reach < DISC_RADIUS_M - 0.01:
            break
    station = parcel_station(rng, first, 1000 * seed + index, [2, 3], (0.85, 1.15))
    at = station.index("--offset")
    station[at + 1:at + 3] = [f"{x[0]:.3f}", f"{y[0]:.3f}"]
    station[station.index("--yaw") + 1] = "0"
    return {
        "name": f"t{seed}_{index}",
        "kind": "pair",
        "args": [*station, "--second-dims", *(f"{d:.3f}" for d in second),
                 "--second-offset", f"{x[1]:.3f}", f"{y[1]:.3f}"],
    }


def run_case(boxd, case):
    with tempfile.TemporaryDirectory() as tmp:
        session = os.path.join(tmp, "session")
        synth = subprocess.run([boxd, "synth", "--out", session, *case["args"]],
                               capture_output=True, text=True)
        if synth.returncode != 0:
            return {**case, "status": "synth failed", "reason": synth.stderr.strip()}
        measured = subprocess.run([boxd, "measure", "--session", session,
                                   *station_config(case, tmp)],
                                  capture_output=True, text=True)
        try:
            result = json.loads(measured.stdout)
        except json.JSONDecodeError:
            return {**case, "status": f"exit {measured.returncode}",
                    "reason": measured.stderr.strip()}
        with open(os.path.join(session, "session.json"), encoding="utf-8") as f:
            truth = json.load(f).get("ground_truth")
    out = {**case, "status": result["status"]}
    if result["status"] != "ok":
        out["reason"] = (result.get("reason") or {}).get("code", "")
        return out
    if truth is None:  # two objects: no size is right
        out["dimensions_mm"] = [1000 * result["dimensions"][k] for k in KEYS]
        return out
    out["error_mm"] = errors_mm(result, truth)
    out["bound_mm"] = [1000 * result["uncertainty_m"][k] for k in KEYS]
    out["shape"] = result["shape"]
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--boxd", default=os.path.join(HERE, "..", "build", "daemon", "boxd"))
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--count", type=int, default=60)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--objects", choices=("boxes", "parcels", "small", "few", "pairs", "shapes"),
                        default="boxes")
    parser.add_argument("--fail-above-mm", type=float)
    parser.add_argument("--one-pose", action="store_true",
                        help="see each object from one pose only, at an angle drawn from SEED")
    parser.add_argument("--effects", action="store_true",
                        help="add one effect of real cameras to each object, drawn from SEED")
    args = parser.parse_args()
    if args.fail_above_mm is None:
        args.fail_above_mm = 5.0 if args.one_pose else {
            "boxes": 1.0, "parcels": 3.0, "small": 2.0, "few": 5.0, "pairs": 0.0,
            "shapes": math.inf}[args.objects]
    rng = random.Random(args.seed)
    draw = {"boxes": draw_case, "parcels": draw_parcel, "small": draw_small, "few": draw_few,
            "pairs": draw_pair, "shapes": draw_shape}[args.objects]
    cases = [draw(rng, i, args.seed) for i in range(args.count)]
    if args.one_pose:
        for case in cases:
            case["args"] += ["--angles", str(rng.randrange(360))]
    if args.effects:
        cases = [draw_effect(rng, case) for case in cases]
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        outcomes = list(pool.map(lambda c: run_case(args.boxd, c), cases))
    measured = [o for o in outcomes if "error_mm" in o]
    for o in outcomes:
        if "dimensions_mm" in o:
            print(f"{o['name']:10s} measured as one object "
                  f"{' x '.join(f'{d:.1f}' for d in o['dimensions_mm'])} mm  {' '.join(o['args'])}")
        elif "error_mm" in o:
            cells = " ".join(f"{e:+6.2f} ({b:4.2f})" for e, b in zip(o["error_mm"], o["bound_mm"]))
            print(f"{o['name']:10s} {cells}  {o['shape']:9s} {o.get('kind', 'box'):10s} {o.get('effect', ''):13s} "
                  f"{' '.join(o['args'])}")
        else:
            print(f"{o['name']:10s} {o['status']} {o.get('reason', '')}  {' '.join(o['args'])}")
    # A drawn object the station cannot hold (off the disc) is no measurement: left out, named.
    unrendered = [o["name"] for o in outcomes if o["status"] == "synth failed"]
    print(f"\nleft out, not rendered: {', '.join(unrendered)}" if unrendered else "", end="")
    outcomes = [o for o in outcomes if o["name"] not in unrendered]
    if args.objects == "pairs":
        answered = [o for o in outcomes if "dimensions_mm" in o]
        refused = sorted(o.get("reason", o["status"]) for o in outcomes if o not in answered)
        print(f"\n{len(answered)} of {len(outcomes)} pairs measured as one object; refused: "
              + ", ".join(f"{r} {refused.count(r)}" for r in sorted(set(refused))))
        return 1 if answered or any(r != "MULTIPLE_OBJECTS" for r in refused) else 0
    if not measured:
        print("no case was measured")
        return 1
    print(f"\n{len(measured)} of {len(outcomes)} measured; refused: "
          + (", ".join(sorted(o.get("reason", o["status"]) for o in outcomes
                              if "error_mm" not in o)) or "none"))
    for k, name in enumerate(("length", "width", "height")):
        errors = [abs(o["error_mm"][k]) for o in measured]
        rms = math.sqrt(sum(e * e for e in errors) / len(errors))
        print(f"{name:6s}: worst |error| {max(errors):.2f} mm, RMS {rms:.2f} mm")
    footprint = [abs(o["error_mm"][k]) for o in measured for k in (0, 1)]
    print(f"footprint errors above 1 mm: {sum(e > 1.0 for e in footprint)} of {len(footprint)}")
    pairs = [(abs(o["error_mm"][k]), o["bound_mm"][k]) for o in measured for k in range(3)]
    within = sum(e <= b for e, b in pairs)
    per_dimension = ", ".join(
        f"{name} {sum(abs(o['error_mm'][k]) <= o['bound_mm'][k] for o in measured)}"
        for k, name in enumerate(("length", "width", "height")))
    print(f"true error within the reported 95% bound: {within} of {len(pairs)} dimensions "
          f"({100.0 * within / len(pairs):.0f}%; {per_dimension} of {len(measured)})")
    print(f"median bound {statistics.median(b for _, b in pairs):.2f} mm, "
          f"median |error| {statistics.median(e for e, _ in pairs):.2f} mm")
    wrong = sum(confidently_wrong(e, b) for e, b in pairs)
    print(f"confident wrong numbers (|error| > 2 x bound + 1 mm): {wrong} of {len(pairs)}")
    for kind in sorted({o["kind"] for o in outcomes if "kind" in o}):
        print("  " + kind_line(kind, [o for o in outcomes if o.get("kind") == kind]))
    if args.objects == "shapes":  # each shape over the sensors, and each sensor over the shapes
        for group in (lambda o: o["kind"].rsplit(" ", 1)[0], lambda o: o["kind"].rsplit(" ", 1)[1]):
            for name in sorted({group(o) for o in outcomes}):
                print("  " + kind_line(name, [o for o in outcomes if group(o) == name]))
    for effect in sorted({o["effect"] for o in outcomes if "effect" in o}):
        print("  " + kind_line(effect, [o for o in outcomes if o.get("effect") == effect]))
    worst = max(e for e, _ in pairs)
    blind = any(o.get("reason") == "NO_OBJECT" for o in outcomes)  # every case shows an object
    if args.objects == "shapes":
        return 1 if wrong or blind else 0
    return 1 if worst > args.fail_above_mm or blind else 0


def kind_line(kind, outcomes):
    """One kind's figures: measured, refused by code, worst error, coverage, confident wrong."""
    measured = [o for o in outcomes if "error_mm" in o]
    refused = sorted(o.get("reason", o["status"]) for o in outcomes if "error_mm" not in o)
    codes = ", ".join(f"{c} {refused.count(c)}" for c in sorted(set(refused))) or "none refused"
    # Refused although the whole object was in view (not cut by the image's border).
    in_view = [o for o in outcomes if o.get("reason") != "OBJECT_TOO_LARGE"]
    if len(in_view) < len(outcomes) or refused:
        codes += (f"; {sum('error_mm' not in o for o in in_view)} of {len(in_view)} in view "
                  "refused")
    mine = [(abs(e), b) for o in measured for e, b in zip(o["error_mm"], o["bound_mm"])]
    if not mine:
        return f"{kind:18s}: 0 of {len(outcomes)} measured ({codes})"
    return (f"{kind:18s}: {len(measured)} of {len(outcomes)} measured ({codes}); worst |error| "
            f"{max(e for e, _ in mine):.2f} mm, {sum(e <= b for e, b in mine)} of {len(mine)} "
            f"within their bound, {sum(confidently_wrong(e, b) for e, b in mine)} confidently "
            f"wrong")


if __name__ == "__main__":
    sys.exit(main())
