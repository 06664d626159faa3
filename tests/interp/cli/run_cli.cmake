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
