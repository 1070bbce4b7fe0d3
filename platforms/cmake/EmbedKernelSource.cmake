# Writes OUTPUT, a C++ file defining OpenMM::CommonSymPRKKernelSources::symprk as the text of INPUT (the Common
# device source), in raw string literals of at most 12,000 characters each (MSVC refuses longer literals).
# Run at build time: cmake -DINPUT=... -DOUTPUT=... -P EmbedKernelSource.cmake
file(READ "${INPUT}" text)
string(LENGTH "${text}" length)
set(body "")
set(start 0)
while(start LESS length)
    string(SUBSTRING "${text}" ${start} 12000 chunk)
    string(APPEND body "    R\"SYMPRKSRC(${chunk})SYMPRKSRC\"\n")
    math(EXPR start "${start} + 12000")
endwhile()
set(content "// Generated from ${INPUT_NAME} by EmbedKernelSource.cmake: do not edit.\n#include \"CommonSymPRKKernels.h\"\nconst std::string SymPRKPlugin::CommonSymPRKKernelSources::symprk = std::string(\n${body});\n")
# Write only when the text changed, so that an unchanged kernel source compiles nothing again.
set(old "")
if(EXISTS "${OUTPUT}")
    file(READ "${OUTPUT}" old)
endif()
if(NOT old STREQUAL content)
    file(WRITE "${OUTPUT}" "${content}")
endif()
