// The light estimator's inputs from the shipped data, as the appliance's sim run has them: the
// default booth (its lamps are the classifier's stored lights) and the simulated spectrometer's
// calibration.
#pragma once

#include <state/scene_estimator.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/scene/booth.h>
#include <pipeline/spectral/spectrometer_chain.h>

#include <gtest/gtest.h>

namespace replica::tests {

inline state::SceneEstimatorSetup shippedEstimatorSetup()
{
    state::SceneEstimatorSetup setup;
    auto booth = pipeline::scene::loadDefaultBooth(dataDir().string());
    auto cal = pipeline::spectral::loadSpectrometerCalibration(dataDir() / "spectrometer" /
                                                               "sim_usb2000_responsivity.csv");
    EXPECT_TRUE(booth) << booth.error().message;
    EXPECT_TRUE(cal) << cal.error().message;
    if (booth && cal) {
        setup.light.booth = *booth;
        setup.light.calibration = *cal;
    }
    return setup;
}

} // namespace replica::tests
