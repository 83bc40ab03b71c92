#!/usr/bin/python3
"""The Sedov-Taylor point blast in an ideal gas: the self-similar solution, computed here.

A energy E released at a point (3D, spherical; D = 3), along a line (2D, cylindrical, E per
unit length; D = 2) or on a plane (D = 1, E per unit area) into gas of uniform density rho0 at
zero pressure drives a strong shock at
    R(t) = xi0 (E t^2 / rho0)^(1/(D+2))
(L. I. Sedov, "Similarity and Dimensional Methods in Mechanics", Academic Press 1959, ch. IV;
G. I. Taylor, Proc. R. Soc. A 201 (1950) 159). With lambda = r/R, U = dR/dt = delta R/t and
delta = 2/(D+2), the flow behind it is
    u = U phi(lambda),  rho = rho0 psi(lambda),  p = rho0 U^2 pi(lambda).
Put into the Euler equations (continuity, momentum, and entropy p rho^-gamma constant along a
particle path; R'' = (delta - 1)/delta U^2/R) these give, with w = phi - lambda and
c^2 = gamma pi/psi,
    w psi' + psi (phi' + (D-1) phi/lambda) = 0
    w phi' + pi'/psi = (D/2) phi
    w (pi'/pi - gamma psi'/psi) = D,
a linear system in (phi', psi', pi') solved at each lambda:
    phi' = [(D/2) phi w - D pi/psi + c^2 (D-1) phi/lambda] / (w^2 - c^2).
They start at the shock from the strong-shock Rankine-Hugoniot state
    phi(1) = 2/(gamma+1),  psi(1) = (gamma+1)/(gamma-1),  pi(1) = 2/(gamma+1)
and are integrated inwards (here RK4 in s = -ln lambda, to lambda = 1e-8). The energy between
the centre and the shock fixes xi0:
    E = sigma_D rho0 U^2 R^D I,  I = int_0^1 (psi phi^2/2 + pi/(gamma-1)) lambda^(D-1) dlambda,
    sigma_D = 2 (D = 1, both sides of the plane), 2 pi (D = 2), 4 pi (D = 3),
so that E = alpha rho0 R^(D+2)/t^2 with alpha = sigma_D delta^2 I and xi0 = alpha^(-1/(D+2)).

Checked (run this file) against J. R. Kamm and F. X. Timmes, "On efficient generation of
numerically robust Sedov solutions", Los Alamos report LA-UR-07-2849 (2007): for gamma = 1.4
their alpha is 0.851060 (spherical; their standard case puts E = 0.851072 so that R = 1 at
t = 1) and 0.984041 (cylindrical, E per unit length); this integration gives 0.8510719 and
0.9840740, so xi0 = 1.03278 (spherical; L. D. Landau and E. M. Lifshitz, "Fluid Mechanics",
2nd ed. 1987, section 106: 1.033 for gamma = 1.4) and 1.00402 (cylindrical).

Pure numpy; runs under Debian's /usr/bin/python3.

    R = shock_radius(t, energy, rho0, dim=3, gamma=1.4)
    rho, u, p = profile(r, t, energy, rho0, dim=3, gamma=1.4)
"""

import functools
import math

import numpy as np

__all__ = ["similarity_solution", "energy_constant", "xi0", "shock_radius", "profile"]

_SIGMA = {1: 2.0, 2: 2.0 * math.pi, 3: 4.0 * math.pi}


def _rates(lam, y, dim, gamma):
    """d/dlambda of (phi, psi, pi) and of the energy integrand's running integral."""
    phi, psi, pi_ = y[0], y[1], y[2]
    w = phi - lam
    c2 = gamma * pi_ / psi
    dphi = (0.5 * dim * phi * w - dim * pi_ / psi + c2 * (dim - 1) * phi / lam) / (w * w - c2)
    dpsi = -psi * (dphi + (dim - 1) * phi / lam) / w
    dpi = pi_ * (dim / w + gamma * dpsi / psi)
    dint = (0.5 * psi * phi * phi + pi_ / (gamma - 1.0)) * lam ** (dim - 1)
    return np.array([dphi, dpsi, dpi, dint])


@functools.lru_cache(maxsize=None)
def similarity_solution(dim, gamma, steps=20000, lam_min=1e-8):
    """(lambda, phi, psi, pi, I(lambda)) from the shock (lambda = 1) inwards to lam_min, on
    `steps` RK4 steps uniform in s = -ln lambda; I(lambda) = int_lambda^1 of the energy
    integrand, so I[-1] is the energy integral I. Cached: treat the arrays as read-only."""
    if dim not in _SIGMA:
        raise ValueError(f"dim must be 1, 2 or 3, not {dim}")
    if not gamma > 1.0:
        raise ValueError(f"gamma must exceed 1, not {gamma}")
    s_end = -math.log(lam_min)
    ds = s_end / steps
    y = np.array([2.0 / (gamma + 1.0), (gamma + 1.0) / (gamma - 1.0), 2.0 / (gamma + 1.0), 0.0])
    out = np.empty((steps + 1, 5))
    out[0] = (1.0, *y)

    # dy/ds = -lambda dy/dlambda; the running integral counts up as lambda goes down.
    def f(s, y):
        lam = math.exp(-s)
        r = lam * _rates(lam, y, dim, gamma)
        r[:3] = -r[:3]
        return r

    s = 0.0
    for k in range(steps):
        k1 = f(s, y)
        k2 = f(s + 0.5 * ds, y + 0.5 * ds * k1)
        k3 = f(s + 0.5 * ds, y + 0.5 * ds * k2)
        k4 = f(s + ds, y + ds * k3)
        y = y + ds / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        s += ds
        out[k + 1] = (math.exp(-s), *y)
    out.setflags(write=False)
    return out[:, 0], out[:, 1], out[:, 2], out[:, 3], out[:, 4]


def energy_constant(dim, gamma, steps=20000):
    """alpha of E = alpha rho0 R^(D+2) / t^2 (E per unit length in 2D, per unit area in 1D)."""
    delta = 2.0 / (dim + 2)
    integral = similarity_solution(dim, gamma, steps)[4][-1]
    return _SIGMA[dim] * delta * delta * integral


def xi0(dim, gamma, steps=20000):
    """xi0 of R = xi0 (E t^2 / rho0)^(1/(D+2))."""
    return energy_constant(dim, gamma, steps) ** (-1.0 / (dim + 2))


def shock_radius(t, energy, rho0, dim, gamma, xi=None):
    """R(t) = xi0 (E t^2 / rho0)^(1/(D+2)); xi (optional) is xi0 computed beforehand."""
    xi = xi0(dim, gamma) if xi is None else xi
    return xi * (energy * np.asarray(t, float) ** 2 / rho0) ** (1.0 / (dim + 2))


def profile(r, t, energy, rho0, dim, gamma):
    """(rho, u, p) at radii r and time t > 0: the self-similar flow inside R(t) (interpolated in
    lambda), the gas at rest at rho0 and zero pressure outside."""
    lam, phi, psi, pi_, _ = similarity_solution(dim, gamma)
    big_r = shock_radius(t, energy, rho0, dim, gamma)
    u_shock = 2.0 / (dim + 2) * big_r / t
    x = np.asarray(r, float) / big_r
    inside = x <= 1.0
    # lambda decreases along the arrays; np.interp needs it increasing.
    rho = np.where(inside, rho0 * np.interp(x, lam[::-1], psi[::-1]), rho0)
    u = np.where(inside, u_shock * np.interp(x, lam[::-1], phi[::-1]), 0.0)
    p = np.where(inside, rho0 * u_shock ** 2 * np.interp(x, lam[::-1], pi_[::-1]), 0.0)
    return rho, u, p


if __name__ == "__main__":
    # Kamm & Timmes (2007), gamma = 1.4: alpha = 0.851060 (spherical), 0.984041 (cylindrical).
    for dim, published in ((3, 0.851060), (2, 0.984041)):
        a = energy_constant(dim, 1.4)
        a_half = energy_constant(dim, 1.4, steps=10000)
        assert abs(a / published - 1.0) < 1e-4, (dim, a, published)
        assert abs(a / a_half - 1.0) < 1e-7, (dim, a, a_half)
        print(f"D = {dim}: alpha = {a:.7f} (Kamm & Timmes 2007: {published}), "
              f"xi0 = {a ** (-1.0 / (dim + 2)):.6f}")
    # Landau & Lifshitz section 106: xi0 = 1.033 for the spherical blast in air.
    assert abs(xi0(3, 1.4) - 1.033) < 5e-4
    print("OK")
