# Runs `cnc check` on bad.nc and good.nc and compares exit status, stdout and stderr with the
# files written by hand next to them (bad.stderr: one line per error, file:line:col: message).
function(expect_run name expected_status)
  execute_process(COMMAND ${CNC} check ${name}.nc WORKING_DIRECTORY ${CASES}
                  RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT status EQUAL ${expected_status})
    message(FATAL_ERROR "cnc check ${name}.nc: exit ${status}, expected ${expected_status}\n${err}")
  endif()
  file(READ ${CASES}/${name}.stdout want_out)
  if(NOT out STREQUAL want_out)
    message(FATAL_ERROR "cnc check ${name}.nc stdout:\n${out}\nexpected:\n${want_out}")
  endif()
  if(EXISTS ${CASES}/${name}.stderr)
    file(READ ${CASES}/${name}.stderr want_err)
    if(NOT err STREQUAL want_err)
      message(FATAL_ERROR "cnc check ${name}.nc stderr:\n${err}\nexpected:\n${want_err}")
    endif()
  endif()
endfunction()

expect_run(bad 1)
expect_run(good 0)
expect_run(warn 0)

# --settings with --save-settings: G92 and G923 are written back (atomically) and survive.
file(MAKE_DIRECTORY ${WORK})
file(WRITE ${WORK}/settings.txt "wcs 2 100 0 0 0 0 0\n")
execute_process(COMMAND ${CNC} canon persist.nc --settings ${WORK}/settings.txt --save-settings
                WORKING_DIRECTORY ${CASES} RESULT_VARIABLE status OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "cnc canon persist.nc: exit ${status}\n${err}")
endif()
file(READ ${WORK}/settings.txt saved)
foreach(want "wcs 2 100 0 0 0 0 0\n" "g92 10 20 0 0 0 0\n" "tool 3 0 0 2.5 0\n")
  string(FIND "${saved}" "${want}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "saved settings lack '${want}':\n${saved}")
  endif()
endforeach()
if(EXISTS ${WORK}/settings.txt.tmp)
  message(FATAL_ERROR "temporary settings file left behind")
endif()
# A bad settings file is a setup error (exit 2) naming file:line:col, and is left untouched.
file(WRITE ${WORK}/bad.txt "g92 1 2\n")
execute_process(COMMAND ${CNC} check good.nc --settings ${WORK}/bad.txt
                WORKING_DIRECTORY ${CASES} RESULT_VARIABLE status OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT status EQUAL 2 OR NOT err MATCHES "bad.txt:1:1: settings: 'g92' needs 6 values, found 2")
  message(FATAL_ERROR "bad settings: exit ${status}, stderr ${err}")
endif()
file(READ ${WORK}/bad.txt bad)
if(NOT bad STREQUAL "g92 1 2\n")
  message(FATAL_ERROR "bad settings file was changed")
endif()
# --use-default-speed (G00-4): the default feed replaces F600; G905 runs at the programmed F.
execute_process(COMMAND ${CNC} canon default_speed.nc --default-feed 1200 --use-default-speed
                WORKING_DIRECTORY ${CASES} RESULT_VARIABLE status OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
set(want "1 feed-rate 20mm/s\n1 feed X10 Y0 Z0\n2 feed-rate 10mm/s\n2 feed X20 Y0 Z0 programmed-feed\n")
string(FIND "${out}" "${want}" at)
if(NOT status EQUAL 0 OR at EQUAL -1)
  message(FATAL_ERROR "cnc canon --use-default-speed: exit ${status}\n${out}\n${err}")
endif()
# Without a default feed the switch has nothing to run at: a setup error before anything runs.
execute_process(COMMAND ${CNC} check default_speed.nc --use-default-speed
                WORKING_DIRECTORY ${CASES} RESULT_VARIABLE status OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT status EQUAL 2 OR NOT err MATCHES "--use-default-speed needs --default-feed MM_PER_MIN")
  message(FATAL_ERROR "--use-default-speed without --default-feed: exit ${status}, stderr ${err}")
endif()
