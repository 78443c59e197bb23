# Writes OUT from IN with the source tree's `git describe --always --dirty` taken at build time.
# Taken at configure time, it went stale: a later commit or edit rebuilt the code but kept the
# old version, so runs recorded a code_version that was not the code that made them.
# configure_file rewrites OUT only when its text changes: an unchanged tree recompiles nothing.
#   cmake -DSRC=<source dir> -DIN=<template> -DOUT=<file> -DPROJECT_VERSION=<x.y.z> -P build_version.cmake
execute_process(COMMAND git describe --always --dirty --abbrev=12
                WORKING_DIRECTORY ${SRC}
                OUTPUT_VARIABLE GRAVSWEEP_GIT_VERSION OUTPUT_STRIP_TRAILING_WHITESPACE
                ERROR_QUIET)
if(NOT GRAVSWEEP_GIT_VERSION)
  set(GRAVSWEEP_GIT_VERSION "unknown")
endif()
configure_file(${IN} ${OUT} @ONLY)
