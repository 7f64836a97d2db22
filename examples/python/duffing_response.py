"""A forced Duffing frequency response from Python, notebook style.

    PYTHONPATH=build/python python3 examples/python/duffing_response.py [out.csv]

Continues the response x'' + 0.1 x' + x + x^3 = F cos(w t) through its folds
for three forcing amplitudes, prints where each folds, saves every branch as
CSV (F, w, amplitude, stable) and, when gnuplot is installed, draws them.
"""
import shutil
import subprocess
import sys

import numpy as np

import rmhb

out = sys.argv[1] if len(sys.argv) > 1 else "duffing_response.csv"
rows = []
for F in (0.2, 0.35, 0.5):
    branch = rmhb.Model("examples/models/duffing.yaml", F=F).continuation("w", 0.5, 3.0, order=15)
    print(f"F = {F}: {branch.parameter.size} points, {branch.status}, folds at w = {np.round(branch.folds, 6)}")
    for w, a, s in zip(branch.parameter, branch.amplitude, branch.stable):
        rows.append((F, w, a, int(s)))
    rows.append((np.nan,) * 4)  # a blank line between branches for gnuplot
np.savetxt(out, rows, delimiter=",", header="F,w,amplitude,stable", comments="", fmt="%.12g")
print(f"wrote {out}")

if shutil.which("gnuplot"):
    png = out.rsplit(".", 1)[0] + ".png"
    script = (f"set terminal pngcairo size 900,600; set output '{png}'; set datafile separator ',';"
              f"set datafile missing 'nan'; set xlabel 'w'; set ylabel 'max |x|'; set key top left;"
              f"plot '{out}' every ::1 using 2:($4 == 1 ? $3 : NaN) with points pt 7 ps 0.6 title 'stable',"
              f"     '{out}' every ::1 using 2:($4 == 0 ? $3 : NaN) with points pt 6 ps 0.6 title 'unstable'")
    subprocess.run(["gnuplot", "-e", script], check=True)
    print(f"drew {png}")
