# Fails unless the README quotes the example program verbatim (its lines from the first #include
# to the end), so the README's code sample is code that CI builds and runs.
file(READ ${EXAMPLE} example)
file(READ ${README} readme)
string(FIND "${example}" "#include" start)
string(SUBSTRING "${example}" ${start} -1 body)
string(FIND "${readme}" "${body}" found)
if(found EQUAL -1)
  message(FATAL_ERROR "README.md does not quote ${EXAMPLE} (from its first #include on): update the README's code sample")
endif()
message(STATUS "README.md quotes ${EXAMPLE}")
