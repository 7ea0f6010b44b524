#pragma once
// Smoke filling the air for part of a run (a fire upwind in a mine roadway), as the colour camera
// sees it. Koschmieder's law per pixel: a surface at distance d along the pixel's ray keeps
// exp(-σ·d) of its radiance, and the smoke between adds its own grey radiance, the airlight A,
// weighted 1 - exp(-σ·d); a pixel that meets nothing within range sees A alone:
//
//   L_pixel = L_surface · exp(-σ·d) + A · (1 - exp(-σ·d))
//
// A is the smoke's albedo times the light that reaches it near the camera: the ambient light, the
// lamps (dimmed by the smoke between them and the camera) and the headlight, which lights the
// smoke right in front of the lens (its backscatter, headlight_backscatter()).
//
// The schedule says when: no smoke, then the extinction σ ramps up (smoothstep) to its dense
// value, holds, and ramps down again. The default schedule has no smoke at all and the camera's
// rendering does not change (World::smoke, the scenarios other than `smoke`).
//
// Only the colour camera sees it: long-wave infrared passes through smoke of small (soot)
// particles far better than visible light, and the lidar model has no volume returns
// (docs/simulator.md, known limits).

namespace posed::sim {

struct SmokeSchedule {
  /// true time since the start [s]: the smoke starts to thicken, is dense, starts to clear,
  /// is gone (start ≤ dense_from ≤ dense_to ≤ clear)
  double start_s = 0, dense_from_s = 0, dense_to_s = 0, clear_s = 0;
  /// extinction coefficient σ while dense [1/m] (0 = no smoke); visibility (5 % contrast) is
  /// 3/σ, so 3 /m leaves 1 m
  double dense_extinction_per_m = 0;
  /// radiance of an optically thick layer of the smoke per unit irradiance, in the colour
  /// camera's units (a Lambertian surface's albedo is the same quantity) [0..1]
  double albedo = 0.25;

  /// whether there is any smoke in the run
  bool any() const { return dense_extinction_per_m > 0 && clear_s > start_s; }
  /// σ at true time `t_s` [1/m]: 0 outside (start, clear), the dense value on
  /// [dense_from, dense_to], smoothstep ramps between
  double extinction_per_m(double t_s) const;
};

/// How bright the headlight makes the smoke it shines into, relative to the airlight of a uniform
/// unit irradiance: σ ∫₀^∞ exp(-2σs) / (1 + s²) ds, the headlight's irradiance at s metres
/// (1/(1 + s²), as World::headlight lights surfaces) attenuated on its way out and the scattered
/// light on its way back. 0 without smoke, 0.31 at σ = 0.5 /m, 0.48 at 3 /m, 1/2 as σ → ∞.
double headlight_backscatter(double extinction_per_m);

}  // namespace posed::sim
