# Fails unless the README quotes the example program verbatim (its lines from the first #include,
# or from the first START text when given, to the end), so the README's code sample is code that
# CI builds and runs.
file(READ ${EXAMPLE} example)
file(READ ${README} readme)
if(NOT DEFINED START)
  set(START "#include")
endif()
string(FIND "${example}" "${START}" start)
string(SUBSTRING "${example}" ${start} -1 body)
string(FIND "${readme}" "${body}" found)
if(found EQUAL -1)
  message(FATAL_ERROR "README.md does not quote ${EXAMPLE} (from its first ${START} on): update the README's code sample")
endif()
message(STATUS "README.md quotes ${EXAMPLE}")
