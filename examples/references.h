#ifndef RMHB_EXAMPLES_REFERENCES_H_
#define RMHB_EXAMPLES_REFERENCES_H_

// References computed independently of harmonic balance, to measure errors
// against: elliptic integrals for the pendulum, the energy quadrature for the
// relativistic oscillator, a tight CVODE period for Van der Pol.

namespace rmhb::examples {

// Complete elliptic integral of the first kind K(m), m = k^2, by the
// arithmetic-geometric mean (quadratically convergent, full precision).
double EllipticK(double m);

// Pendulum theta'' + sin(theta) = 0 released from rest at theta0 (|theta0| < pi).
double PendulumFrequency(double theta0);  // pi / (2 K(sin^2(theta0/2)))
// theta(t) from its exact Fourier series in the nome q:
//   theta(t) = 8 sum_n (-1)^n q^(n+1/2) / ((2n+1)(1 + q^(2n+1))) cos((2n+1) w t).
double PendulumAngle(double theta0, double t);
// Cosine coefficient of harmonic n (zero for even n) of the same series.
double PendulumCoefficient(double theta0, int n);

// Relativistic oscillator x'' + (1 - x'^2)^(3/2) x = 0, x(0) = 0, x'(0) = beta.
// gamma + x^2/2 is conserved, so A = sqrt(2 (gamma0 - 1)); with x = A sin(phi)
// the period integral T = 4 int_0^{pi/2} (1 + A^2 cos^2/2)/sqrt(1 + A^2 cos^2/4)
// has a smooth periodic integrand and the trapezoid rule converges
// geometrically.
double RelativisticAmplitude(double beta);
double RelativisticPeriod(double beta);

// Van der Pol x'' - eps (1 - x^2) x' + x = 0: the limit-cycle period CVODE
// measures between successive maxima of x once the orbit has settled (BDF at
// the tightest practical tolerance, event detection polished to round-off,
// averaged over ten periods). For eps = 10 it matches the published
// 19.07836956693901407 to 6e-12; its own uncertainty is ~5e-11 up to eps = 20.
double VanDerPolPeriodByCvode(double eps);

}  // namespace rmhb::examples

#endif  // RMHB_EXAMPLES_REFERENCES_H_
