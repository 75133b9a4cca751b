# Link Abseil, protobuf and gRPC (with gRPC's c-ares, re2, upb and
# address_sorting) from their static archives (Debian ships both).
#
# Why: a process linked against the shared ones loads ~80 libraries and
# spends most of a small run's start-up in the dynamic loader, resolving
# ~22,000 symbol relocations of those C++ libraries (measured: `LD_DEBUG=
# statistics`, `valgrind --tool=callgrind`; docs/honest-runs.md has the
# figures). Linked statically, those references are resolved once, at link
# time. The C libraries (OpenSSL, zlib, zstd, SQLite, libpq and its
# Kerberos/LDAP) stay shared: libpq.so brings its own libssl/libcrypto, so
# linking a second, static copy of OpenSSL beside it would mix two.
#
# Every target of the build uses the same choice, so no process mixes a
# static and a shared copy of one library. Off for the sanitizer and fuzz
# builds (uninstrumented Debian libraries stay as they are there).

set(_cablesim_static_default ON)
if(CABLESIM_SANITIZE OR CABLESIM_FUZZ)
  set(_cablesim_static_default OFF)
endif()
option(CABLESIM_STATIC_DEPS
       "Link Abseil, protobuf and gRPC from their static archives (faster start-up)"
       ${_cablesim_static_default})

# The static archive beside shared library `location`, or "" if none.
function(_cablesim_static_archive location out)
  set(archive "")
  if(location MATCHES "^(.*)\\.so(\\.[0-9.]+)?$")
    if(EXISTS "${CMAKE_MATCH_1}.a")
      set(archive "${CMAKE_MATCH_1}.a")
    endif()
  endif()
  set(${out} "${archive}" PARENT_SCOPE)
endfunction()

function(cablesim_use_static_deps)
  if(NOT CABLESIM_STATIC_DEPS)
    return()
  endif()
  get_directory_property(imported DIRECTORY ${CMAKE_SOURCE_DIR} IMPORTED_TARGETS)
  set(switched 0)
  foreach(t IN LISTS imported)
    if(NOT t MATCHES "^(absl|protobuf|gRPC|c-ares|re2)::")
      continue()
    endif()
    get_target_property(type ${t} TYPE)
    if(type STREQUAL "SHARED_LIBRARY" OR type STREQUAL "UNKNOWN_LIBRARY")
      foreach(prop IMPORTED_LOCATION IMPORTED_LOCATION_NONE IMPORTED_LOCATION_NOCONFIG
                   IMPORTED_LOCATION_RELEASE IMPORTED_LOCATION_RELWITHDEBINFO
                   IMPORTED_LOCATION_MINSIZEREL IMPORTED_LOCATION_DEBUG)
        get_target_property(location ${t} ${prop})
        if(location)
          _cablesim_static_archive("${location}" archive)
          if(archive)
            set_target_properties(${t} PROPERTIES ${prop} "${archive}")
            math(EXPR switched "${switched} + 1")
          endif()
        endif()
      endforeach()
    elseif(t STREQUAL "re2::re2" AND type STREQUAL "INTERFACE_LIBRARY")
      # gRPC's Findre2 makes re2::re2 an interface naming `re2` (-lre2).
      find_library(_cablesim_re2_archive NAMES libre2.a)
      if(_cablesim_re2_archive)
        set_target_properties(re2::re2 PROPERTIES INTERFACE_LINK_LIBRARIES
                                                   "${_cablesim_re2_archive}")
        math(EXPR switched "${switched} + 1")
      endif()
    endif()
  endforeach()
  message(STATUS "cablesim: ${switched} Abseil/protobuf/gRPC libraries linked statically "
                 "(CABLESIM_STATIC_DEPS)")
endfunction()
