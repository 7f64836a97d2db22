"""The Python module as a script uses it (run by ctest: python3 -m pytest tests/python).

Every name of the module is exercised; results are checked against the CLI
(to the last bit), against a CVODE integration, or against a signal whose
frequencies are known exactly.
"""
import json
import sys
import math
import os
import subprocess
import threading
import time

import numpy as np
import pytest

import rmhb

CLI = os.environ.get("RMHB_CLI", "build/rmhb")
DUFFING = "examples/models/duffing.yaml"


def cli_json(*args):
    out = subprocess.run([CLI, *args, "--json"], check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def test_frequency_equals_the_cli_to_the_last_bit():
    vdp = rmhb.Model("examples/models/vanderpol.yaml", eps=1.5)
    s = vdp.solve(order=30)
    assert s.converged and s.status == "converged"
    ref = cli_json("solve", "examples/models/vanderpol.yaml", "--set", "eps=1.5", "--order", "30")
    assert s.frequencies[0] == ref["frequencies"][0]  # bit for bit, not approximately
    assert s.order == 30 and s.residual < 1e-12 and s.seconds > 0
    assert json.loads(s.to_json())["frequencies"][0] == ref["frequencies"][0]


def test_eval_on_a_numpy_grid_equals_the_cli_eval(tmp_path):
    m = rmhb.Model(DUFFING, F=0.5)
    s = m.solve(order=20)
    csv = tmp_path / "eval.csv"
    subprocess.run([CLI, "solve", DUFFING, "--set", "F=0.5", "--order", "20", "--eval", "0:0.25:10",
                    "--csv", str(csv)], check=True, capture_output=True)
    table = np.genfromtxt(csv, delimiter=",", names=True)
    values = s.eval(table["t"])
    assert set(values) == {"x", "x_d1"}
    np.testing.assert_array_equal(values["x"], table["x"])
    np.testing.assert_array_equal(values["x_d1"], table["x_d1"])


def test_a_recast_that_fails_falls_back_on_the_original_equations_like_the_cli():
    model = "tests/pipeline/models/steep-friction.yaml"
    s = rmhb.Model(model).solve(order=100)
    ref = cli_json("solve", model, "--order", "100")
    assert ref["equations"] == "original" and s.converged
    assert set(s.coefficients) == {"x", "x_d1"}  # the original equations' variables: no tanh auxiliary
    assert s.frequencies[0] == ref["frequencies"][0]
    np.testing.assert_array_equal(s.coefficients["x"][0], ref["coefficients"]["x"]["cos"])
    v = s.validate()
    assert v["ok"] and v["max_error"] < 1e-5  # N = 100: the kink-like term's truncation, ~8e-6


def test_coefficients_harmonics_validate_and_stability():
    s = rmhb.Model(DUFFING, F=0.5).solve(order=20)
    cos, sin = s.coefficients["x"]
    assert cos.shape == sin.shape == (21,) and sin[0] == 0
    assert s.harmonics.shape == (21, 1) and s.harmonics[5, 0] == 5
    # x(0) from the coefficients equals eval at t = 0.
    assert math.isclose(cos.sum(), s.eval(np.array([0.0]))["x"][0], rel_tol=1e-13)
    v = s.validate(periods=2)
    assert v["ok"] and v["max_error"] < 1e-8
    st = s.stability()
    assert st["verdict"] in ("stable", "unstable") and st["hill"] == st["monodromy"]
    assert st["max_multiplier_difference"] < 1e-6


def test_stability_of_a_torus_is_hills_exponent_checked_by_lyapunov():
    s = rmhb.Model("examples/models/forced-vanderpol.yaml").solve()
    assert s.converged and len(s.frequencies) == 2
    st = s.stability()
    assert st["verdict"] == st["hill"] == st["lyapunov"] == "stable"
    # Liouville: the transverse exponent is eps (1 - <x^2>), Parseval from the coefficients.
    cos, sin = s.coefficients["x"]
    mean_square = cos[0] ** 2 + 0.5 * (np.sum(cos[1:] ** 2) + np.sum(sin[1:] ** 2))
    assert math.isclose(st["largest_exponent"], 0.2 * (1 - mean_square), abs_tol=1e-9)
    assert st["max_exponent_difference"] < 5e-3 and "hill_multipliers" in st


def test_a_non_physical_solution_is_not_called_converged():
    # HDHB aliasing on the relativistic oscillator (the CLI exits 5 on it).
    s = rmhb.Model("relativistic", beta=0.99).solve(order=12, method="hdhb", start="guess")
    assert s.status == "non_physical" and not s.converged
    assert json.loads(s.to_json())["physical"] is False


def test_continuation_gives_numpy_columns_and_the_folds():
    b = rmhb.Model("duffing", F=0.5).continuation("w", 0.5, 3.0, order=15)
    assert b.status == "completed"
    n = b.parameter.shape[0]
    assert b.frequency.shape == b.amplitude.shape == b.stable.shape == (n,)
    assert b.stable.dtype == np.bool_
    assert b.frequencies.shape == (n, 1) and (b.frequencies[:, 0] == b.frequency).all()
    ref = cli_json("solve", "duffing", "--set", "F=0.5", "--order", "15", "--continue", "w=0.5:3")
    np.testing.assert_allclose(b.folds, ref["folds"], rtol=1e-12)
    assert len(b.folds) == 2 and (~b.stable).sum() > 3


def test_continuation_reports_the_bifurcations_like_the_cli():
    model = "tests/pipeline/models/quadratic-duffing.yaml"
    b = rmhb.Model(model).continuation("w", 2.5, 1.5, order=12)
    assert b.status == "completed" and "none" not in b.stability_method
    ref = cli_json("solve", model, "--order", "12", "--continue", "w=2.5:1.5")
    assert [d["type"] for d in b.bifurcations] == ["period_doubling"] * 2
    for mine, cli in zip(b.bifurcations, ref["bifurcations"]):
        assert mine["parameter"] == pytest.approx(cli["parameter"], rel=1e-12)
        assert mine["located"] and abs(mine["multiplier"] + 1) < 1e-8


def test_analyze_and_simulate():
    a = rmhb.Model("vanderpol").analyze(order=40)
    assert a.ok and a.status == "converged" and a.validation_error < 1e-8  # over 20 periods
    ref = cli_json("analyze", "vanderpol", "--order", "40")
    assert a.frequencies[0] == ref["frequencies"][0]
    assert a.validation_error == ref["stages"]["validate"]["max_error"]
    assert "validate" in a.report()
    sim = rmhb.Model("duffing").simulate(t_end=10.0, dt=0.5)
    assert list(sim) == ["t", "x", "x'"] and sim["t"].shape == (21,) and sim["t"][-1] == 10.0


def test_identify_a_two_tone_signal_to_1e12():
    t = np.arange(8192) * 0.05
    w1, w2 = 1.0, math.sqrt(2.0)
    x = np.cos(w1 * t + 0.3) + 0.3 * np.sin(w2 * t)
    result = rmhb.identify(t, x)
    assert result.status == "success"
    np.testing.assert_allclose(np.sort(result.bases), [w1, w2], rtol=0, atol=1e-12)
    assert {tuple(sorted(map(abs, line["label"]))) for line in result.lines} == {(0, 1)}
    two_channels = rmhb.identify(t, np.c_[x, 2 * x])
    assert len(two_channels.lines[0]["amplitude"]) == 2


def test_errors_are_python_exceptions(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: bad\nvariables: [x]\nequations:\n  - \"x'' + sin(thta) = 0\"\nfrequencies: [{guess: 1}]\n")
    with pytest.raises(rmhb.ModelError, match=r"bad.yaml:4:\d+: unknown symbol 'thta'"):
        rmhb.Model(str(bad))
    assert issubclass(rmhb.ModelError, ValueError)
    with pytest.raises(ValueError, match="no parameter 'nope'"):
        rmhb.Model("duffing", nope=1.0)
    with pytest.raises(ValueError, match="method must be"):
        rmhb.Model("duffing").solve(method="galerkin")
    with pytest.raises(ValueError, match="order or p"):
        rmhb.Model("duffing").solve(order=5, p=5)
    with pytest.raises(ValueError, match="unknown linear solver 'lu'"):
        rmhb.Model("duffing").solve(order=5, linear_solver="lu")
    with pytest.raises(TypeError):
        rmhb.Model("duffing").solve(order="five")
    with pytest.raises(ValueError, match="uniformly spaced"):
        rmhb.identify(np.r_[np.arange(100) * 0.1, 20.0], np.zeros(101))


def test_solves_release_the_gil():
    # While a long solve runs in a thread, Python code keeps running here:
    # with the GIL held for the whole solve this loop would stall for as long
    # as the solve takes (the longest gap between two turns shows it).
    # The dense LU keeps the solve long enough to tell (Newton-Krylov, which
    # auto takes at these 1602 unknowns, finishes it in ~20 ms; dense ~0.3 s).
    m = rmhb.Model("vanderpol", eps=5.0)
    done = []
    worker = threading.Thread(target=lambda: done.append(m.solve(order=800, linear_solver="dense")))
    last, longest_gap = time.perf_counter(), 0.0  # before start(): the stall may come at once
    worker.start()
    while worker.is_alive():  # a stall may sit inside is_alive(): the last gap counts too
        now = time.perf_counter()
        longest_gap, last = max(longest_gap, now - last), now
    longest_gap = max(longest_gap, time.perf_counter() - last)
    worker.join()
    assert done and done[0].converged
    solve = done[0].seconds
    assert solve > 0.05, "the solve was too short to tell"
    assert longest_gap < 0.5 * solve, f"this thread stalled {longest_gap:.3f} s of a {solve:.3f} s solve: the GIL was held"
    # The same orbit by Newton-Krylov (--linear-solver's choices reach Python too).
    krylov = m.solve(order=800, linear_solver="krylov")
    assert abs(krylov.frequencies[0] - done[0].frequencies[0]) < 1e-12 * done[0].frequencies[0]


def test_binding_overhead_is_under_ten_percent_of_a_small_solve():
    m = rmhb.Model("pendulum")
    best_wall, best_solve = math.inf, math.inf
    for _ in range(7):
        start = time.perf_counter()
        s = m.solve(order=25)
        wall = time.perf_counter() - start
        if wall < best_wall:
            best_wall, best_solve = wall, s.seconds
    # What the binding adds around the library's solve: argument conversion,
    # the CLI-equivalent settings, the result object (model loading included,
    # as the CLI does it per solve).
    print(f"pendulum N = 25: solve {best_solve * 1e3:.3f} ms, call {best_wall * 1e3:.3f} ms")
    assert best_wall < 1.10 * best_solve + 3e-4  # 10 %, plus 0.3 ms for timer noise


def test_the_example_script_runs(tmp_path):
    out = tmp_path / "response.csv"
    run = subprocess.run([sys.executable, "examples/python/duffing_response.py", str(out)], capture_output=True, text=True,
                         env={**os.environ}, check=True)
    assert "folds at w" in run.stdout
    data = np.genfromtxt(out, delimiter=",", names=True)
    assert np.nansum(data["stable"] == 0) > 3 and np.nanmax(data["amplitude"]) > 2


def test_a_users_file_without_conditions_or_guess_gets_the_clis_defaults(tmp_path):
    # The hardening Duffing oscillator from x = 1 at rest, nothing else given:
    # the orbit through initial_state (rmhb/METHOD.md s.20), as the CLI.
    model = tmp_path / "hardening.yaml"
    model.write_text('variables: [x]\nequations: ["x\'\' + x + x^3 = 0"]\n'
                     'frequencies: [{guess: 1}]\ninitial_state: {x: 1, "x\'": 0}\n')
    s = rmhb.Model(str(model)).solve()
    assert s.converged
    ref = cli_json("solve", str(model))
    assert s.frequencies[0] == ref["frequencies"][0]
    assert json.loads(s.to_json())["default_conditions"] == ref["default_conditions"]
    k = 1.685750354812596  # K(m = 1/4), the elliptic closed form
    assert abs(s.frequencies[0] - math.pi * math.sqrt(2) / (2 * k)) < 1e-12
