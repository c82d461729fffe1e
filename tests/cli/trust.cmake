# Step 9, the command line a user can trust: outputs checked before any work,
# interrupts that keep what was rendered, no silent mistakes, the defaults a
# user expects. Included from tests/CMakeLists.txt (VRL_CLI, CLI_CHECK set there).
set(TRUST_SCENE ${PROJECT_SOURCE_DIR}/scenes/smoke-room.xml)
set(TRUST_DIR ${CMAKE_CURRENT_BINARY_DIR}/trust)
set(TRUST_SMALL --resolution 16x12 --spp 1 --vrls 500)
file(MAKE_DIRECTORY ${TRUST_DIR})
# A copy of the scene to aim -o at: if the check ever regresses, only the copy is lost.
configure_file(${TRUST_SCENE} ${TRUST_DIR}/scene-copy.xml COPYONLY)

# Outputs: refused with exit 2, naming the path and the reason, within 2 s (timeout exits 124);
# the two timed ones are labelled `timed` (the sanitizer job leaves them out: instrumentation
# slows start-up; cli.unwritable_output and cli.preview_missing_folder_refused check the same untimed).
add_test(NAME cli.output_missing_folder_refused_fast
  COMMAND ${CLI_CHECK} 2 "no/such/dir/x.exr.*folder '/no/such/dir' does not exist"
          timeout 2 ${VRL_CLI} render ${TRUST_SCENE} -o /no/such/dir/x.exr)
set_tests_properties(cli.output_missing_folder_refused_fast PROPERTIES LABELS "e2e;timed")
add_test(NAME cli.output_is_the_scene_refused
  COMMAND ${CLI_CHECK} 2 "scene-copy.xml' is the scene's input file"
          ${VRL_CLI} render ${TRUST_DIR}/scene-copy.xml -o ${TRUST_DIR}/scene-copy.xml)
add_test(NAME cli.output_extension_refused
  COMMAND ${CLI_CHECK} 2 "-o '.*x.png': the file name must end in .exr"
          ${VRL_CLI} render ${TRUST_SCENE} -o ${TRUST_DIR}/x.png)
add_test(NAME cli.preview_extension_refused
  COMMAND ${CLI_CHECK} 2 "--preview '.*p.exr': the file name must end in .png"
          ${VRL_CLI} render ${TRUST_SCENE} -o ${TRUST_DIR}/x.exr --preview ${TRUST_DIR}/p.exr)
add_test(NAME cli.preview_missing_folder_refused
  COMMAND ${CLI_CHECK} 2 "--preview '/no/such/p.png': the folder '/no/such' does not exist"
          ${VRL_CLI} render ${TRUST_SCENE} -o ${TRUST_DIR}/x.exr --preview /no/such/p.png)
add_test(NAME cli.output_is_a_folder_refused
  COMMAND ${CLI_CHECK} 2 "is a directory"
          ${VRL_CLI} render ${TRUST_SCENE} -o ${TRUST_DIR}/folder.exr)
file(MAKE_DIRECTORY ${TRUST_DIR}/folder.exr)
add_test(NAME cli.submit_output_checked_before_connecting
  COMMAND ${CLI_CHECK} 2 "folder '/no/such/dir' does not exist"
          timeout 2 ${VRL_CLI} submit ${TRUST_SCENE} -o /no/such/dir/x.exr --coordinator 127.0.0.1:9)
set_tests_properties(cli.submit_output_checked_before_connecting PROPERTIES LABELS "e2e;timed")

# Interrupts: partial EXR with coverage, exit 130/143, a second Ctrl-C quits at once.
add_test(NAME cli.interrupt_keeps_partial_image
  COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/cli/interrupt_test.sh ${VRL_CLI} ${TRUST_SCENE} ${TRUST_DIR}/interrupt)
set_tests_properties(cli.interrupt_keeps_partial_image PROPERTIES COST 35)

# No silent mistakes.
add_test(NAME cli.flag_without_effect_warns_error_with_path
  COMMAND ${CLI_CHECK} 0 "--error has no effect with --method path"
          ${VRL_CLI} render ${TRUST_SCENE} -o ${TRUST_DIR}/path.exr ${TRUST_SMALL} --method path --error 0.1)
add_test(NAME cli.flag_without_effect_warns_tile_size_embedded
  COMMAND ${CLI_CHECK} 0 "--tile-size has no effect without --workers"
          ${VRL_CLI} render ${TRUST_SCENE} -o ${TRUST_DIR}/tile.exr ${TRUST_SMALL} --tile-size 8)
add_test(NAME cli.flag_without_effect_warns_vrls_with_light_paths
  COMMAND ${CLI_CHECK} 0 "--vrls has no effect with --light-paths"
          ${VRL_CLI} render ${TRUST_SCENE} -o ${TRUST_DIR}/paths.exr --resolution 16x12 --spp 1 --vrls 500
          --light-paths 50)
add_test(NAME cli.memory_estimate_refused_before_work
  COMMAND ${CLI_CHECK} 2 "--vrls 4294967296: the VRLs and their light structures need about [0-9.]+ GiB.*lower --vrls"
          timeout 5 ${VRL_CLI} render ${TRUST_SCENE} -o ${TRUST_DIR}/huge.exr --vrls 4294967296)
add_test(NAME cli.seed_negative_refused
  COMMAND ${CLI_CHECK} 2 "--seed: must be a decimal integer"
          ${VRL_CLI} render ${TRUST_SCENE} -o ${TRUST_DIR}/x.exr --seed -1)
add_test(NAME cli.seed_not_decimal_refused
  COMMAND ${CLI_CHECK} 2 "--seed: must be a decimal integer" ${VRL_CLI} render ${TRUST_SCENE} -o ${TRUST_DIR}/x.exr --seed 1e3)
add_test(NAME cli.seed_above_2_64_refused
  COMMAND ${CLI_CHECK} 2 "--seed: is above 2\\^64-1"
          ${VRL_CLI} render ${TRUST_SCENE} -o ${TRUST_DIR}/x.exr --seed 18446744073709551616)
add_test(NAME cli.threads_zero_documented_everywhere
  COMMAND ${CLI_CHECK} 0 "0 \\(the default\\) = all cores" ${VRL_CLI} render --help)
add_test(NAME cli.worker_threads_zero_documented
  COMMAND ${CLI_CHECK} 0 "--threads.*0: all cores" $<TARGET_FILE:vrl-worker> --help)
add_test(NAME cli.coordinator_threads_zero_documented
  COMMAND ${CLI_CHECK} 0 "--threads.*0: all cores" $<TARGET_FILE:vrl-coordinator> --help)

# Defaults: headline method, jitter, single-channel counters, VPL naming, quiet, stdout.
add_test(NAME cli.defaults_and_streams
  COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/cli/defaults_test.sh ${VRL_CLI} ${TRUST_SCENE} ${TRUST_DIR}/defaults)
set_tests_properties(cli.defaults_and_streams PROPERTIES LABELS heavy COST ${VRL_HEAVY_COST})

# The job is built locally by the coordinator's own builder before anything starts or is sent:
# a crop outside the film is bad input (exit 2) for --workers and submit as for the embedded render.
add_test(NAME cli.workers_bad_crop_refused_before_start
  COMMAND ${CLI_CHECK} 2 "crop window 30,0,16,12.*does not fit inside the 40x30 film"
          timeout 5 ${VRL_CLI} render ${TRUST_SCENE} -o ${TRUST_DIR}/crop.exr --resolution 40x30 --crop 30,0,16,12
          --workers 2)
add_test(NAME cli.submit_bad_crop_refused_before_connecting
  COMMAND ${CLI_CHECK} 2 "crop window 30,0,16,12.*does not fit inside the 40x30 film"
          timeout 5 ${VRL_CLI} submit ${TRUST_SCENE} -o ${TRUST_DIR}/crop.exr --resolution 40x30 --crop 30,0,16,12
          --coordinator 127.0.0.1:9)
add_test(NAME cli.submit_flag_without_effect_warns
  COMMAND ${CLI_CHECK} 1 "--error has no effect with --method path.*UNAVAILABLE"
          ${VRL_CLI} submit ${TRUST_SCENE} -o ${TRUST_DIR}/x.exr --method path --error 0.1 --coordinator 127.0.0.1:9
          --retry-for 0)
