# Toolchain file for the bare-metal Cortex-M builds of the pyins core.
#   cmake -S . -B build-m7 -G Ninja -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi.cmake -DPYINS_TARGET_CPU=cortex-m7
#   cmake -S . -B build-m4 -G Ninja -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi.cmake -DPYINS_TARGET_CPU=cortex-m4
# Cortex-M7: fpv5-d16, doubles in hardware. Cortex-M4F: fpv4-sp-d16, doubles
# in software (soft-float library calls), same bits (no FMA contraction).
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_CXX_COMPILER arm-none-eabi-g++)
if(NOT PYINS_TARGET_CPU)
  set(PYINS_TARGET_CPU cortex-m7)
endif()
set(PYINS_TARGET_CPU ${PYINS_TARGET_CPU} CACHE STRING "cortex-m7 or cortex-m4")
if(PYINS_TARGET_CPU STREQUAL "cortex-m7")
  set(_fpu "-mfpu=fpv5-d16")
elseif(PYINS_TARGET_CPU STREQUAL "cortex-m4")
  set(_fpu "-mfpu=fpv4-sp-d16")
else()
  message(FATAL_ERROR "PYINS_TARGET_CPU must be cortex-m7 or cortex-m4, got ${PYINS_TARGET_CPU}")
endif()
set(CMAKE_C_FLAGS_INIT "-mcpu=${PYINS_TARGET_CPU} -mthumb ${_fpu} -mfloat-abi=hard -ffunction-sections -fdata-sections")
set(CMAKE_CXX_FLAGS_INIT "${CMAKE_C_FLAGS_INIT}")
set(CMAKE_EXE_LINKER_FLAGS_INIT "-Wl,--gc-sections")
