"""Peers of `cargo bench --bench fit_scaling`: the same fits by numpy and scipy, timed as whole processes.

    python3 benches/peers/fit_peer.py 3l  POINTS.csv   # numpy: the 3L least-squares problem, degree 4
    python3 benches/peers/fit_peer.py odr POINTS.csv   # scipy.odr: orthogonal-distance fit of the same model

POINTS.csv has rows y,z,ny,nz (a point of a closed profile and its outward unit normal). Both fits work in the
normalised frame zeroset uses (centroid at the origin, unit RMS radius). The 3L system has one data row per point
(target 0) and two offset rows at +-c along the normal (targets +-c), c = 0.01 of the RMS radius, solved by
numpy.linalg.lstsq (LAPACK's SVD-based gelsd). The orthogonal fit is scipy.odr's implicit model
F(beta, x) = 0, started from that 3L answer with the constant coefficient held fixed (the gauge: F and lambda F
have the same zero set); its RMS distance is the RMS of ODRPACK's orthogonal corrections, in mm.
Prints one line: the RMS distance in mm (odr) or the coefficient norm (3l), for a check that the work was done.
"""

import sys

import numpy as np

DEGREE = 4
OFFSET = 0.01


def exponents(degree):
    # The order of zeroset's basis: by total degree, then by descending power of the first variable.
    return [(total - j, j) for total in range(degree + 1) for j in range(total + 1)]


def design(points, degree):
    # Monomials by recurrence on the powers of each variable (one pass over the points per power).
    y, z = points[:, 0], points[:, 1]
    py = [np.ones_like(y)]
    pz = [np.ones_like(z)]
    for _ in range(degree):
        py.append(py[-1] * y)
        pz.append(pz[-1] * z)
    return np.stack([py[a] * pz[b] for a, b in exponents(degree)], axis=1)


def main():
    kind, path = sys.argv[1], sys.argv[2]
    data = np.loadtxt(path, delimiter=",")
    points, normals = data[:, :2], data[:, 2:4]
    centre = points.mean(axis=0)
    scale = np.sqrt(((points - centre) ** 2).sum(axis=1).mean())
    unit = (points - centre) / scale
    rows = np.concatenate([unit, unit + OFFSET * normals, unit - OFFSET * normals])
    target = np.concatenate([np.zeros(len(unit)), np.full(len(unit), OFFSET), np.full(len(unit), -OFFSET)])
    coeffs, *_ = np.linalg.lstsq(design(rows, DEGREE), target, rcond=None)
    if kind == "3l":
        print(f"{np.linalg.norm(coeffs):.9e}")
        return
    from scipy import odr

    def f(beta, x):
        return design(x.T, DEGREE) @ beta

    model = odr.Model(f, implicit=True)
    fixed = np.ones(len(coeffs), dtype=int)
    fixed[0] = 0
    run = odr.ODR(odr.Data(unit.T, 1), model, beta0=coeffs, ifixb=fixed, maxit=100)
    out = run.run()
    rms = np.sqrt((out.delta ** 2).sum(axis=0).mean()) * scale
    print(f"{rms:.9e}")


if __name__ == "__main__":
    main()
