/* Part of the multibin elevation-mapping library. */
#pragma once

namespace multibin::sensors {

/** Range standard deviation as a function of range: sigma_r(r) = c0 + c1 r + c2 r^2 [m].
 *
 * The defaults are the conservative Hokuyo URG-04LX curve of the paper's Fig. 2B: about 1 mm at
 * 0.1 m rising to about 4.5 mm at 1 m (the largest standard deviation over five surfaces at a
 * 30 deg incidence angle). */
struct RangeSigmaCurve {
    double c0_m = 0.0006;   //!< [m]
    double c1 = 0.0039;     //!< [m/m]
    double c2_per_m = 0.0;  //!< [m/m^2]

    double operator()(double range_m) const { return c0_m + (c1 + c2_per_m * range_m) * range_m; }
};

}  // namespace multibin::sensors
