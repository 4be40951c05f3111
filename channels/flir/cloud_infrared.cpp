// FLIR cloud cover: grey-body clouds at their lapse-rate temperature through the path.
#include "channels/flir/cloud_infrared.h"

#include <algorithm>

#include "scene/core/check.h"

namespace seasense::channels {

CloudCover FlirCloudCover(const FlirCloudOptics& optics, const glm::dvec3& eye, const glm::dvec3& d,
                          const scene::CloudHit& hit) {
    CHECK(optics.table != nullptr && optics.transmittance);
    const glm::dvec3 entry = eye + d * hit.distance_m;
    const double T_K = scene::AirTemperature_K(optics.surfaceAir_K, entry.z, 0.0);
    const double range_m =
        EquivalentHorizontalPath_m(hit.distance_m, entry.z - eye.z, kWaterVapourScaleHeight_m);
    const double tauPath = optics.transmittance(range_m);
    const double source =
        tauPath * optics.table->Radiance(T_K) + (1.0 - tauPath) * optics.airRadiance;
    const double eps = scene::CloudInfraredEmissivity(hit.opticalDepth);
    CloudCover c;
    c.alpha = float(eps);
    c.premultiplied[0] = float(eps * source);
    return c;
}

}  // namespace seasense::channels
