#include "engine/forces/winch_inertia.h"

#include "engine/elements/gauss_quadrature.h"
#include "engine/elements/hermite_shape.h"

namespace cablesim {

WinchElementInertia ComputeWinchElementInertia(double mu, double l, int k) {
  static const GaussRule rule = MakeGaussRule(5);
  WinchElementInertia out;
  Eigen::Matrix4d ss = Eigen::Matrix4d::Zero(), ss_l = ss, sw = ss, sw_l = ss, ww = ss;
  for (int g = 0; g < rule.n; ++g) {
    const double xi = rule.xi[g], wt = rule.weight[g];
    double s[4], d1[4], s_l[4];
    HermiteShape(xi, l, s);
    HermiteShapeD1(xi, l, d1);
    HermiteShape(xi, 1.0, s_l);  // dS/dl: the slope functions' factor l
    s_l[0] = s_l[2] = 0;
    const double c = xi + k;
    Eigen::Vector4d sv(s[0], s[1], s[2], s[3]), slv(s_l[0], s_l[1], s_l[2], s_l[3]);
    Eigen::Vector4d w, w_l;
    for (int a = 0; a < 4; ++a) w(a) = s_l[a] - c * d1[a];
    // d(S')/dl: the position functions' 1/l.
    w_l << c * d1[0] / l, 0, c * d1[2] / l, 0;
    ss.noalias() += wt * sv * sv.transpose();
    ss_l.noalias() += wt * (slv * sv.transpose() + sv * slv.transpose());
    sw.noalias() += wt * sv * w.transpose();
    sw_l.noalias() += wt * (slv * w.transpose() + sv * w_l.transpose());
    ww.noalias() += wt * w * w.transpose();
  }
  out.m = mu * l * ss;
  out.m_l = mu * ss + mu * l * ss_l;
  out.g = mu * l * sw;
  out.g_l = mu * sw + mu * l * sw_l;
  out.h = mu * l * ww;
  return out;
}

void WinchConvectiveCoefficients(const WinchElementInertia& in, double ldot, double lddot,
                                 Eigen::Matrix4d* cv, Eigen::Matrix4d* ce) {
  *cv = ldot * (in.m_l + in.g - in.g.transpose());
  *ce = lddot * in.g + ldot * ldot * (in.g_l - in.h);
}

void WinchSlopeRateShape(double xi, double l, int k, double wd[4]) {
  double d1[4], d2[4];
  HermiteShapeD1(xi, l, d1);
  HermiteShapeD2(xi, l, d2);
  const double c = xi + k;
  wd[0] = -d1[0] / l - c * d2[0];
  wd[1] = -c * d2[1];
  wd[2] = -d1[2] / l - c * d2[2];
  wd[3] = -c * d2[3];
}

}  // namespace cablesim
