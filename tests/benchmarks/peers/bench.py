#!/usr/bin/env python3
"""rmhb against SciPy shooting and NLvib on four small periodic problems, in one run.

  tests/benchmarks/peers/bench [--rmhb build/rmhb] [--nlvib DIR] [problem ...]

Problems (model files in tests/benchmarks/peers/models/):
  pendulum         theta'' + sin(theta) = 0, theta(0) = 1.5: error |w - pi/(2K(m))|
  relativistic     x'' + (1 - x'^2)^(3/2) x = 0, x'(0) = 0.85: max(|A - A_exact|, |w - w_exact|)
                   (energy 1/sqrt(1 - v^2) + x^2/2 conserved; period by quadrature)
  duffing          x'' + 0.1 x' + x + x^3 = cos(1.5 t), 20 harmonics
  forced-pendulum  th'' + 0.1 th' + sin(th) = 0.5 cos(0.8 t), 20 harmonics
The forced problems' error is max over a period (257 points) of |x(t) - x_ref(t)|, the
reference an alias-free RHB solve at N = 60 (truncation below round-off), checked against
a SciPy DOP853 shooting at rtol 1e-13 (printed).

Times: rmhb's `seconds` from `rmhb solve --json` (one cold solve in a fresh process, what a
CLI user sees; the median of 9 processes), the whole process's wall time (median), and the
library call (median of warm solves, tests/benchmarks/peer_problems_benchmark); SciPy's and NLvib's the median of repeated solves
in their own process. Needs Debian's python3-scipy and octave (apt-get install python3-scipy
octave), and NLvib: git clone https://github.com/maltekrack/NLvib and pass --nlvib DIR or set
NLVIB_DIR (its SRC/ is added to Octave's path). A missing peer is reported and skipped.
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
PROBLEMS = ["pendulum", "relativistic", "duffing", "forced-pendulum"]
# rmhb's settings per problem: the order and the equations (rmhb/pipeline/model.h).
RMHB = {
    "pendulum": {"order": 25, "equations": "auto"},
    "relativistic": {"order": 55, "equations": "auto"},
    "duffing": {"order": 20, "equations": "auto"},
    "forced-pendulum": {"order": 20, "equations": "auto"},
}


def model_file(name):
    return os.path.join(HERE, "models", name + ".yaml")


def series(cos, sin, w, times):
    out = []
    for t in times:
        v = cos[0]
        for k in range(1, len(cos)):
            v += cos[k] * math.cos(k * w * t) + sin[k] * math.sin(k * w * t)
        out.append(v)
    return out


def exact(name):
    if name == "pendulum":
        from scipy.special import ellipk
        m = math.sin(0.75) ** 2
        return {"frequency": math.pi / (2 * ellipk(m))}
    if name == "relativistic":
        from scipy.integrate import quad
        beta = 0.85
        energy = 1 / math.sqrt(1 - beta * beta)
        amplitude = math.sqrt(2 * (energy - 1))

        # x = A sin(phi): gamma - 1 = (A^2 - x^2)/2 = A^2 cos^2(phi)/2 exactly, and dx / v
        # becomes gamma sqrt(2 / (gamma + 1)) dphi: smooth, no cancellation near x = A.
        def integrand(phi):
            gamma = 1 + 0.5 * (amplitude * math.cos(phi)) ** 2
            return gamma * math.sqrt(2 / (gamma + 1))
        quarter, _ = quad(integrand, 0, math.pi / 2, epsabs=0, epsrel=2e-14, limit=200)
        return {"frequency": 2 * math.pi / (4 * quarter), "amplitude": amplitude}
    return None


def run_rmhb_cli(rmhb, name, order, equations, repeats=1):
    """`rmhb solve --json` in `repeats` fresh processes: the last output, with the
    median of the reported `seconds` and of the processes' wall times."""
    cmd = [rmhb, "solve", model_file(name), "--order", str(order), "--equations", equations, "--json"]
    seconds, walls = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        p = subprocess.run(cmd, capture_output=True, text=True)
        walls.append(time.perf_counter() - t0)
        if p.returncode not in (0, 5, 6):
            raise RuntimeError(" ".join(cmd) + " failed: " + p.stderr.strip())
        out = json.loads(p.stdout)
        seconds.append(out["seconds"])
    out["seconds"] = sorted(seconds)[len(seconds) // 2]
    out["wall"] = sorted(walls)[len(walls) // 2]
    return out


def hb_error(name, cos, sin, w, ref):
    if name == "pendulum":
        return abs(w - ref["frequency"])
    if name == "relativistic":
        # x(0) = 0 at the start: the amplitude is x at a quarter period (x odd in t).
        amplitude = max(abs(v) for v in series(cos, sin, w, [math.pi / (2 * w)]))
        return max(abs(amplitude - ref["amplitude"]), abs(w - ref["frequency"]))
    x = series(cos, sin, w, ref["times"])
    return max(abs(a - b) for a, b in zip(x, ref["x"]))


def median_library_seconds(binary, name, order, equations):
    p = subprocess.run([binary, model_file(name), str(order), equations], capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(binary + " failed: " + p.stderr.strip())
    return json.loads(p.stdout.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rmhb", default=os.path.join(ROOT, "build", "rmhb"))
    ap.add_argument("--nlvib", default=os.environ.get("NLVIB_DIR", ""))
    ap.add_argument("problems", nargs="*", default=PROBLEMS)
    args = ap.parse_args()
    library = os.path.join(os.path.dirname(args.rmhb), "tests", "benchmarks", "peer_problems_benchmark")
    try:
        import scipy  # noqa: F401
        have_scipy = True
    except ImportError:
        have_scipy = False
        print("SciPy: not found (Debian: apt-get install python3-scipy); its column is skipped")
    octave = shutil.which("octave")
    have_nlvib = bool(octave) and os.path.isfile(os.path.join(args.nlvib, "SRC", "HB_residual.m"))
    if not have_nlvib:
        print("NLvib: " + ("octave not found (apt-get install octave); " if not octave else "") +
              "needs --nlvib DIR or NLVIB_DIR=DIR, a clone of https://github.com/maltekrack/NLvib; skipped")

    rows = []
    for name in args.problems:
        s = RMHB[name]
        ref = exact(name) if have_scipy else None
        if name in ("duffing", "forced-pendulum"):
            r = run_rmhb_cli(args.rmhb, name, 60, "recast")
            w = r["frequencies"][0]
            T = 2 * math.pi / w
            ref = {"times": [T * i / 256 for i in range(257)]}
            c = r["coefficients"][next(iter(r["coefficients"]))]
            ref["x"] = series(c["cos"], c["sin"], w, ref["times"])
        row = {"problem": name, "order": s["order"]}
        r = run_rmhb_cli(args.rmhb, name, s["order"], s["equations"], repeats=9)
        var = next(iter(r["coefficients"]))
        c = r["coefficients"][var]
        w = r["frequencies"][0]
        row["rmhb"] = {"seconds": r["seconds"], "wall": r["wall"], "equations": r.get("equations", "?"),
                       "unknowns_note": r.get("equations_note", ""), "status": r["status"],
                       "error": hb_error(name, c["cos"], c["sin"], w, ref) if ref else float("nan")}
        if os.path.isfile(library):
            lib = median_library_seconds(library, name, s["order"], s["equations"])
            row["rmhb"]["library"] = lib["warm_seconds"]
            row["rmhb"]["load"] = lib["load_seconds"]
            row["rmhb"]["cold"] = lib["cold_seconds"]
        if have_scipy:
            p = subprocess.run([sys.executable, os.path.join(HERE, "scipy_shooting.py"), name],
                               capture_output=True, text=True, check=True)
            sp = json.loads(p.stdout)
            if name == "pendulum":
                err = abs(sp["frequency"] - ref["frequency"])
            elif name == "relativistic":
                err = max(abs(sp["amplitude"] - ref["amplitude"]), abs(sp["frequency"] - ref["frequency"]))
            else:
                err = max(abs(a - b) for a, b in zip(sp["x"], ref["x"]))
                row["reference_check"] = err
            row["scipy"] = {"seconds": sp["seconds"], "error": err}
        if have_nlvib:
            p = subprocess.run([octave, "--no-gui", "--quiet", "--eval",
                                "nlvib_bench('%s', {'%s'})" % (args.nlvib, name)],
                               capture_output=True, text=True, cwd=HERE)
            line = [l for l in p.stdout.splitlines() if l.startswith(name + " ")]
            if line:
                v = [float(x) for x in line[0].split()[1:]]
                seconds, w, X = v[0], v[1], v[2:]
                H = (len(X) - 1) // 2
                cos = [X[0]] + [X[2 * k - 1] for k in range(1, H + 1)]
                sin = [0.0] + [X[2 * k] for k in range(1, H + 1)]
                row["nlvib"] = {"seconds": seconds, "error": hb_error(name, cos, sin, w, ref)}
            else:
                row["nlvib"] = {"seconds": float("nan"), "error": float("nan"), "failed": p.stderr.strip()[-200:]}
        rows.append(row)
        print(json.dumps(row), file=sys.stderr, flush=True)

    print()
    print("%-16s %-3s | %-44s | %-19s | %-19s | %s" % ("problem", "N", "rmhb: solve --json seconds (library warm), error",
                                                     "SciPy DOP853 shoot", "NLvib (Octave)", "speed-up"))
    for row in rows:
        r = row["rmhb"]
        lib = " (%.3f ms)" % (1e3 * r["library"]) if "library" in r else ""
        cells = ["%-16s %-3d | %8.3f ms%s %-8s %8.1e" % (row["problem"], row["order"], 1e3 * r["seconds"], lib,
                                                           r["equations"], r["error"])]
        ratios = []
        for peer in ("scipy", "nlvib"):
            if peer in row:
                p = row[peer]
                cells.append("%8.3f ms %8.1e" % (1e3 * p["seconds"], p["error"]))
                ratios.append("%s %.0fx" % (peer, p["seconds"] / r["seconds"]))
            else:
                cells.append("%-19s" % "-")
        print(" | ".join(cells) + " | " + ", ".join(ratios))
    print()
    for row in rows:
        r = row["rmhb"]
        extra = "; load (parse, recast, compile) %.2f ms, cold first solve %.3f ms" % (1e3 * r["load"], 1e3 * r["cold"]) \
            if "load" in r else ""
        check = "; reference vs SciPy %.1e" % row["reference_check"] if "reference_check" in row else ""
        print("%-16s rmhb process wall %.1f ms%s%s" % (row["problem"], 1e3 * r["wall"], extra, check))


if __name__ == "__main__":
    main()
