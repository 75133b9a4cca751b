# The `heavy` label (CTest script, included after every test is discovered:
# tests/CMakeLists.txt adds it to TEST_INCLUDE_FILES last).
#
# Fast-labelled tests that take 10 s or more in the sanitizer build: many
# steps of numerics, which run 25 to 40 times slower there (Debug, -O1,
# AddressSanitizer: no inlining of Eigen's small fixed-size products) than
# in Release, where they take 0.3 to 8 s. On build-asan at 5387e05
# (2026-11-27, 2 cores): these 54 take about 38 minutes in all (19 of them
# timed there, 846 s; the others estimated at 38 times their Release
# time, ErrorGrowthTest's measured ratio: 234 s against 6.1 s), while the
# 904 other fast tests took 616 s.
# CI's sanitizer step leaves them out (`-LE "slow|heavy"`); the Release build
# runs them on every CI run, and the same code paths run under the
# sanitizers through the lighter tests of the same files (scenes of a few
# elements and steps). heavy_label_test fails when a name here matches no
# test (a renamed test would silently come back into the sanitizer step).
#
# A test that stays fast-labelled keeps `fast` beside `heavy`, so
# `ctest -L fast` still runs it.
set(CABLESIM_HEAVY_TESTS
  [=[AlphaStepperTest.FreshNewtonFinishesOnItsLastMatrixAtTheSameAnswer]=]
  [=[AlphaStepperTest.SecondOrderInPositions]=]
  [=[AutoIntegratorTest.AdaptiveChangesToHhtWhereTheStableStepMakesExplicitCostlier]=]
  [=[AutoIntegratorTest.AdaptiveStaysExplicitWhereItsAccuracyHoldsTheStep]=]
  [=[AutoIntegratorTest.AdaptiveStepsStayBelowWhereNewtonFailed]=]
  [=[AutoIntegratorTest.SwitchesToHhtWhenTheSceneStiffensAndBackWhenItSoftens]=]
  [=[Cases/VerticalTest.TensionCarriesPayloadAndCableWeight/pay_out_PLANAR_HHT]=]
  [=[Cases/VerticalTest.TensionCarriesPayloadAndCableWeight/pay_out_PLANAR_IMPLICIT_EULER]=]
  [=[Cases/VerticalTest.TensionCarriesPayloadAndCableWeight/reel_in_PLANAR_GENERALIZED_ALPHA]=]
  [=[Cases/VerticalTest.TensionCarriesPayloadAndCableWeight/reel_in_PLANAR_HHT]=]
  [=[Cases/VerticalTest.TensionCarriesPayloadAndCableWeight/reel_in_SPATIAL_HHT]=]
  [=[CoupledBodyPrescribedTest.TheHostsMotionGivesThePrescribedMotionsForces]=]
  [=[DampingTest.BackwardEulerDissipationStaysApart]=]
  [=[DenseOutputTest.DampedEnergyBetweenStepsIsAsAccurateAsAtStepEnds]=]
  [=[DenseOutputTest.InterpolatedFramesAreAsAccurateAsStepEnds]=]
  [=[DynamicsTest.FallingPendulumEnergyNeverIncreasesUnderBackwardEuler]=]
  [=[DynamicsTest.MeshConvergenceOfTheFallingPendulumTip]=]
  [=[EnergyMomentumStepperTest.AdaptiveStepsMeetTheTolerance]=]
  [=[EnergyMomentumStepperTest.FallingPendulumKeepsItsEnergyToTheNewtonTolerance]=]
  [=[EnergyMomentumStepperTest.TipConvergesAtSecondOrder]=]
  [=[ErrorGrowthTest.AccumulatedEstimateBoundsTheEndCylindersErrorWhereTheLocalOneCannot]=]
  [=[ErrorGrowthTest.TheEndCylindersErrorAtTheEndIsMadeBeforeTheWhipAndGrownByIt]=]
  [=[ExplicitStepperTest.CentralDifferenceConvergesAtSecondOrder]=]
  [=[ExplicitStepperTest.DampedPendulumAgreesWithAnImplicitReference]=]
  [=[ExplicitStepperTest.DormandPrinceConvergesAtFifthOrder]=]
  [=[ExplicitStepperTest.FallingPendulumAgreesWithAnImplicitReference]=]
  [=[JointSnapTest.PeakTensionConvergesAndMatchesTheSuddenLoad]=]
  [=[Models/PendulumTest.FollowsTheVariableLengthPendulum/"PLANAR"]=]
  [=[Models/PendulumTest.FollowsTheVariableLengthPendulum/"SPATIAL"]=]
  [=[MoorDynWaveKinTest.EveryDeckRuns]=]
  [=[RequestCostingTest.ARunBuildsItsModelOnce]=]
  [=[SeabedFrictionTest.ASlidingChainCostsNewtonFewIterations]=]
  [=[SeabedFrictionTest.MoorDynLawPullsWithItsClosedForm]=]
  [=[SeabedTest.BedDampingCostsNewtonAboutWhatAnUndampedBedDoes]=]
  [=[SeabedTest.MooringStaticsWithFrictionMatchesTheCatenaryWithCB]=]
  [=[SeabedTest.OscillatingFairleadKeepsTheStepOfAFreeCable]=]
  [=[SeabedTest.TouchdownPointConvergesWithTheMesh]=]
  [=[ServerRetentionTest.DeletedResultsShrinkTheDatabaseFile]=]
  [=[ShapeCliTest.ShapeFlagAsksForTheShape]=]
  [=[SlidingJointTest.ZipLineSceneRuns]=]
  [=[TensionTableTest.EnergyMomentumKeepsEnergyWithATable]=]
  [=[WaveLoadTest.RiserInWavesStepsAsInStillWaterWithItsEnergyBalanced]=]
  [=[WinchEnergyTest.BackwardEulerLossIsPositiveAndFirstOrder]=]
  [=[WinchEnergyTest.HhtLossIsSmallPositiveAndShrinksWithTheStep]=]
  [=[WinchEnergyTest.SlowLiftWorkIsTheStaticEnergyStored]=]
  [=[WinchEnergyTest.TrapezoidalConservesToTheNewtonFloor]=]
  [=[WinchFluidTest.LoweringInStillWaterCarriesTheSubmergedWeight]=]
  [=[WinchFluidTest.PayingOutOntoTheSeabedTheBedCarriesTheGroundedWeight]=]
  [=[WinchFluidTest.SplashZoneEnergyBalances]=]
  [=[WinchFluidTest.SplashZoneEnergyBalancesWithDragInACurrent]=]
  [=[WinchFluidTest.SplashZoneTensionChangesByTheDisplacedWeightPerMetre]=]
  [=[WinchFluidTest.TangentialDragActsOnTheMaterialVelocity]=]
  [=[WinchTest.CraneSceneRuns]=]
  [=[WinchTest.PayOutThenReelInReturnsThePayload]=]
)
set_tests_properties(${CABLESIM_HEAVY_TESTS} PROPERTIES LABELS "fast;heavy")
