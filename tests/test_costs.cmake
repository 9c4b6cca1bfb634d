# The longest tests, as ctest COST: their seconds under the sanitizers (build-asan, RelWithDebInfo,
# `ctest -j 2` on the 2-core machine). `ctest -j` starts the costliest first; without this a fresh
# build directory (no Testing/Temporary/CTestCostData.txt yet, as in CI) starts them in the order
# they were added, and the run ends with cli.dry_run and cli.match_fake_board (mostly waiting on
# the clock) running alone. Order only: no test's command or result changes.
# Read twice: by tests/CMakeLists.txt at configure time for the tests add_test adds there
# (SLAMO_TEST_COSTS_AT_CONFIGURE), and by ctest (TEST_INCLUDE_FILES) for those that
# gtest_discover_tests lists at build time; a name not defined yet is skipped.
set(slamo_test_costs
  cli.dry_run=88
  cli.match_fake_board=48
  vision.ColourClassesTest.ThresholdBgrMatchesHsvOnEveryColour=34
  cli.experiment_robustness=26
  cli.case_study_writes_object_map=21
  Executive.ARobotStartingInsideTheMarginDrivesOutAhead=18
  Executive.TheV5RobotScoresInOverUnderAndPushBack=17
  Executive.FullDryRunScoresWithinTheDeadlineAndMapsItsObjects=16
  HardwareMatch.ClosesTheLoopOverTheFakeBoardsSerialLink=11
  HardwareMatch.SurvivesAnUnpluggedCableAndANoisyLink=11
  # twice its 10 views' 11 s, since it renders 20 (not re-measured under the sanitizers)
  VisionEvalTest.FlatFacesAreNotTakenForRoundObjects=22
  planning.ReferencePathTest.OmplPathsAreNoShorterThanTheReference=10
  VisionEvalTest.StarsAreFoundWholeOnlyWithTheSizeRule=9
  VisionEvalTest.DeterministicPerSeedAndTheCleanFieldHasLittleToReject=8
  cli.detect=7
  VisionEvalTest.ArenaPrecisionIsBetterWithTheFieldGate=7
  Executive.AnObjectThatScoresNothingIsDroppedToFreeTheIntake=7
  RecordingRun.ReplaysASimulatedRecordingWithinTenCentimetres=6
  Replay.FramesShowTheCameraBesideTheMap=6
  mapping.AdaptiveEkfTest.FirstEstimatesJacobiansMapBetterWhereTheModelIsRight=5
  VisionEvalTest.PilesAreCountedWithTheSplitBySize=5)
foreach(entry IN LISTS slamo_test_costs)
  string(REPLACE "=" ";" entry "${entry}")
  list(GET entry 0 test_name)
  list(GET entry 1 test_cost)
  if(NOT SLAMO_TEST_COSTS_AT_CONFIGURE)
    # ctest: set_tests_properties skips a name it does not know.
    set_tests_properties("${test_name}" PROPERTIES COST ${test_cost})
  elseif(TEST "${test_name}")
    set_tests_properties("${test_name}" PROPERTIES COST ${test_cost})
  endif()
endforeach()
