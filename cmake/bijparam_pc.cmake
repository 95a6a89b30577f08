# bijparam_pc.cmake - write bijparam.pc from bijparam.pc.in at install time
# (included by the install script, where CMAKE_INSTALL_PREFIX is the prefix
# actually installed to, `cmake --install --prefix` included).
#
# In: BP_PC_IN, BP_PC_OUT, BP_PC_INCLUDEDIR_REL (CMAKE_INSTALL_INCLUDEDIR),
# BP_PC_VERSION.  includedir is written relative to ${prefix} unless it is
# absolute, as `make install` does.
set(BP_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
if(IS_ABSOLUTE "${BP_PC_INCLUDEDIR_REL}")
  set(BP_PC_INCLUDEDIR "${BP_PC_INCLUDEDIR_REL}")
else()
  set(BP_PC_INCLUDEDIR "\${prefix}/${BP_PC_INCLUDEDIR_REL}")
endif()
configure_file("${BP_PC_IN}" "${BP_PC_OUT}" @ONLY)
