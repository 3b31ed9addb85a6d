# Fails when BINARY needs libtorch or a library only libtorch brings (its c10, the CPU kernels,
# OpenCV and FFmpeg of Debian's build, ...): `skinlab-predict` must start without them.
#   cmake -DBINARY=<program> -P cmake/check_no_torch.cmake
if(NOT BINARY OR NOT EXISTS "${BINARY}")
  message(FATAL_ERROR "check_no_torch.cmake: pass -DBINARY=<an existing program>, got '${BINARY}'")
endif()
execute_process(COMMAND ldd "${BINARY}" OUTPUT_VARIABLE libraries RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "ldd ${BINARY} failed (${status})")
endif()
# Library names only: ldd's load addresses are random hex ("(0x00007ffd4c10a000)").
string(REGEX MATCHALL "lib(torch|c10|caffe2|gloo|dnnl|opencv|avcodec|avformat)[^ \t\n]*\\.so[^ \t\n]*"
       found "${libraries}")
list(LENGTH found count)
string(REGEX MATCHALL "\n" lines "${libraries}")
list(LENGTH lines total)
if(count GREATER 0)
  string(REPLACE ";" "\n" found "${found}")
  message(FATAL_ERROR "${BINARY} needs ${count} libtorch libraries:\n${found}")
endif()
message(STATUS "${BINARY}: ${total} shared libraries, none of libtorch's")
