#!/usr/bin/env python3
"""SciPy's answer to the four bench problems: DOP853 shooting.

Autonomous, conservative (pendulum, relativistic oscillator): integrate from
the given state with a terminal event on the Poincare section x' = 0 (the
quarter or half period), which gives the period and the amplitude directly.
Forced (Duffing, damped pendulum): Newton on the initial state y0 with
F(y0) = y(T) - y0 = 0, the Jacobian (monodromy matrix) from the variational
equations integrated alongside. Prints one JSON object per problem:
{"problem", "seconds" (median of repeats), "state" (y at t = 0), "period", ...}.
"""
import json
import math
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp

RTOL, ATOL = 1e-13, 1e-15


def median_seconds(f, budget=1.0, at_least=3, at_most=200):
    times = []
    begin = time.perf_counter()
    while len(times) < at_least or (len(times) < at_most and time.perf_counter() - begin < budget):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    times.sort()
    return times[len(times) // 2]


def pendulum(theta0=1.5):
    def rhs(t, y):
        return [y[1], -math.sin(y[0])]

    def event(t, y):
        return y[1]
    event.terminal, event.direction = True, 1.0  # theta' crosses 0 upwards: half a period

    def solve():
        s = solve_ivp(rhs, (0, 100), [theta0, 0.0], method="DOP853", rtol=RTOL, atol=ATOL, events=event)
        return 2 * s.t_events[0][0]

    period = solve()
    return {"problem": "pendulum", "seconds": median_seconds(solve), "frequency": 2 * math.pi / period,
            "state": [theta0, 0.0]}


def relativistic(beta=0.85):
    def rhs(t, y):
        return [y[1], -(1 - y[1] ** 2) ** 1.5 * y[0]]

    def event(t, y):
        return y[1]
    event.terminal, event.direction = True, -1.0  # x' falls through 0 at the turning point: a quarter period

    def solve():
        s = solve_ivp(rhs, (0, 100), [0.0, beta], method="DOP853", rtol=RTOL, atol=ATOL, events=event)
        return 4 * s.t_events[0][0], s.y_events[0][0][0]

    period, amplitude = solve()
    return {"problem": "relativistic", "seconds": median_seconds(solve), "frequency": 2 * math.pi / period,
            "amplitude": amplitude, "state": [0.0, beta]}


def forced(name, force, w, y0):
    """Newton on y(T) - y0 with the variational equations; force(t, x, v) gives x''
    and its exact partials in x and v (finite differences would put noise into the
    right-hand side, and DOP853 at rtol 1e-13 then takes a million steps)."""
    T = 2 * math.pi / w

    def partials(t, x, v):
        return force(t, x, v)

    def rhs(t, y):
        x, v = y[0], y[1]
        f, fx, fv = partials(t, x, v)
        # y[2:6]: the 2x2 monodromy, column-major, d/dt Phi = A Phi.
        p = y[2:6]
        return [v, f, p[1], fx * p[0] + fv * p[1], p[3], fx * p[2] + fv * p[3]]

    def solve():
        # Newton until the step no longer shrinks or is at the integration's own
        # accuracy (rtol 1e-13): a tighter test is never met and only costs periods.
        y = np.array(y0, dtype=float)
        previous = np.inf
        for _ in range(20):
            s = solve_ivp(rhs, (0, T), [y[0], y[1], 1, 0, 0, 1], method="DOP853", rtol=RTOL, atol=ATOL)
            end = s.y[:, -1]
            F = end[:2] - y
            J = np.array([[end[2], end[4]], [end[3], end[5]]]) - np.eye(2)
            dy = np.linalg.solve(J, -F)
            y = y + dy
            step = np.max(np.abs(dy))
            if step < 1e-12 * (1 + np.max(np.abs(y))) or step > 0.5 * previous and step < 1e-9:
                break
            previous = step
        return y

    y = solve()
    return {"problem": name, "seconds": median_seconds(solve), "frequency": w, "state": list(y)}


def trajectory(name, y0, w, times):
    """The shooting solution's own orbit at `times` (for the error over a period)."""
    if name == "duffing":
        def rhs(t, y):
            return [y[1], math.cos(w * t) - 0.1 * y[1] - y[0] - y[0] ** 3]
    else:
        def rhs(t, y):
            return [y[1], 0.5 * math.cos(w * t) - 0.1 * y[1] - math.sin(y[0])]
    s = solve_ivp(rhs, (0, times[-1]), y0, method="DOP853", rtol=RTOL, atol=ATOL, t_eval=times)
    return s.y[0].tolist()


def main():
    which = sys.argv[1:] or ["pendulum", "relativistic", "duffing", "forced-pendulum"]
    for name in which:
        if name == "pendulum":
            out = pendulum()
        elif name == "relativistic":
            out = relativistic()
        elif name == "duffing":
            out = forced("duffing", lambda t, x, v: (math.cos(1.5 * t) - 0.1 * v - x - x ** 3, -1 - 3 * x * x, -0.1),
                         1.5, [1.5, 0.0])
        elif name == "forced-pendulum":
            out = forced("forced-pendulum",
                         lambda t, x, v: (0.5 * math.cos(0.8 * t) - 0.1 * v - math.sin(x), -math.cos(x), -0.1),
                         0.8, [-2.2, 0.9 * 0.8])
        else:
            raise SystemExit("unknown problem " + name)
        if name in ("duffing", "forced-pendulum"):
            T = 2 * math.pi / out["frequency"]
            out["times"] = [T * i / 256 for i in range(257)]
            out["x"] = trajectory(name, out["state"], out["frequency"], out["times"])
        print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
