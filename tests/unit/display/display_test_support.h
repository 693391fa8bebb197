// Shared by the display tests: one fitted profile of the synthetic IPS panel, fitted once.
#pragma once

#include <pipeline/base/assert.h>
#include <pipeline/offline/display/display_fit.h>
#include <pipeline/offline/display/synthetic_display.h>

namespace replica::pipeline::display::test {

inline const DisplayModel& fittedSyntheticIps()
{
    static const DisplayModel model = [] {
        MeasurementSet set;
        set.source = "synthetic";
        set.bitDepth = 8;
        set.rows = syntheticMeasurements(wideIpsGroundTruth(), MeterNoise{}, 1);
        FitOptions o;
        o.name = "test-ips";
        auto m = fitDisplay(set, o);
        REPLICA_ASSERT(m.has_value(), "the synthetic set must fit");
        m->viewing = wideIpsViewingAngles();
        return *m;
    }();
    return model;
}

} // namespace replica::pipeline::display::test
