#!/usr/bin/python3
"""SciPy's vectorised differential evolution on the same LuGre identification problem as
jg_bench_identify: same data (CSV w,friction), same bounds, same evaluation budget
(population x generations ~ 200 x 300), same objective (mean squared error of the
implicit-Euler LuGre prediction, paper eq. 13, in bristle-torque form). Prints JSON."""
import json
import sys
import time

import numpy as np
from scipy.optimize import differential_evolution

DT = 0.008


def load(path):
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    return data[:, 0], data[:, 1]


def make_objective(w, r):
    def objective(x):
        x = np.atleast_2d(x.T).T  # (6, S) with vectorized=True
        sigma0, sigma1, sigma2, tau_c, tau_s, w_s = x
        gain = sigma0 * DT
        damping = sigma1 / gain
        zeta = np.zeros_like(sigma0)
        acc = np.zeros_like(sigma0)
        for wk, rk in zip(w, r):
            level = tau_c + (tau_s - tau_c) * np.exp(-(wk / w_s) ** 2)
            speed = abs(wk)
            g = gain / (level + gain * speed)
            nxt = zeta + (wk * level - zeta * speed) * g
            tau = nxt + damping * (nxt - zeta) + sigma2 * wk
            zeta = nxt
            acc += (rk - tau) ** 2
        return acc / len(w)
    return objective


def main():
    w, r = load(sys.argv[1])
    bounds = [(60000.0, 100000.0), (1e-6, 500.0), (1e-6, 10.0), (1e-6, 10.0), (1e-6, 10.0), (1e-6, 0.1)]
    popsize = 34  # x 6 parameters = 204 individuals per generation
    maxiter = 294  # (maxiter + 1) x 204 ~ 60,000 evaluations = the GA's 200 x 301
    t0 = time.perf_counter()
    res = differential_evolution(make_objective(w, r), bounds, popsize=popsize, maxiter=maxiter, tol=0.0,
                                 atol=0.0, polish=False, vectorized=True, updating="deferred", seed=1)
    secs = time.perf_counter() - t0
    print(json.dumps({"scipy_seconds": round(secs, 4), "scipy_objective": float(res.fun),
                      "scipy_objective_calls": int(res.nfev),
                      "scipy_evaluations": int(res.nfev) * popsize * 6, "scipy_tau_c": float(res.x[3])}))


if __name__ == "__main__":
    main()
