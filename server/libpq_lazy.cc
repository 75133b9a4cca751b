// libpq, loaded on first use.
//
// Linked normally, libpq.so.5 brings ~20 shared libraries into every
// process (Kerberos, LDAP, SASL, GnuTLS and theirs), which the dynamic
// loader maps and relocates at start-up: ~4 ms of CPU per process measured
// (docs/honest-runs.md), although only a server with a PostgreSQL job store
// ever calls it. These definitions of the libpq functions this project
// calls (the declarations are libpq-fe.h's, so a signature that drifts
// does not compile) load libpq.so.5 with dlopen at the first call and
// forward to it. A libpq function used for the first time must be added
// here (the link says which is missing).

#include <dlfcn.h>
#include <libpq-fe.h>

#include <cstdio>
#include <cstdlib>

namespace {

void* Libpq() {
  static void* const handle = [] {
    void* h = dlopen("libpq.so.5", RTLD_NOW | RTLD_LOCAL);
    if (h == nullptr) {
      std::fprintf(stderr, "cablesim: cannot load libpq.so.5 (PostgreSQL job store): %s\n",
                   dlerror());
      std::abort();
    }
    return h;
  }();
  return handle;
}

void* LibpqSymbol(const char* name) {
  void* symbol = dlsym(Libpq(), name);
  if (symbol == nullptr) {
    std::fprintf(stderr, "cablesim: libpq.so.5 has no %s: %s\n", name, dlerror());
    std::abort();
  }
  return symbol;
}

}  // namespace

#define CABLESIM_LIBPQ(ret, name, params, args)                                      \
  ret name params {                                                                  \
    static const auto real = reinterpret_cast<decltype(&name)>(LibpqSymbol(#name)); \
    return real args;                                                                \
  }

CABLESIM_LIBPQ(PGconn*, PQconnectdb, (const char* conninfo), (conninfo))
CABLESIM_LIBPQ(void, PQfinish, (PGconn * conn), (conn))
CABLESIM_LIBPQ(void, PQreset, (PGconn * conn), (conn))
CABLESIM_LIBPQ(char*, PQdb, (const PGconn* conn), (conn))
CABLESIM_LIBPQ(char*, PQuser, (const PGconn* conn), (conn))
CABLESIM_LIBPQ(char*, PQhost, (const PGconn* conn), (conn))
CABLESIM_LIBPQ(char*, PQport, (const PGconn* conn), (conn))
CABLESIM_LIBPQ(ConnStatusType, PQstatus, (const PGconn* conn), (conn))
CABLESIM_LIBPQ(char*, PQerrorMessage, (const PGconn* conn), (conn))
CABLESIM_LIBPQ(int, PQsocket, (const PGconn* conn), (conn))
CABLESIM_LIBPQ(PGresult*, PQexec, (PGconn * conn, const char* query), (conn, query))
CABLESIM_LIBPQ(PGresult*, PQexecParams,
               (PGconn * conn, const char* command, int n_params, const Oid* param_types,
                const char* const* param_values, const int* param_lengths,
                const int* param_formats, int result_format),
               (conn, command, n_params, param_types, param_values, param_lengths, param_formats,
                result_format))
CABLESIM_LIBPQ(int, PQconsumeInput, (PGconn * conn), (conn))
CABLESIM_LIBPQ(PGnotify*, PQnotifies, (PGconn * conn), (conn))
CABLESIM_LIBPQ(ExecStatusType, PQresultStatus, (const PGresult* res), (res))
CABLESIM_LIBPQ(char*, PQresultErrorMessage, (const PGresult* res), (res))
CABLESIM_LIBPQ(char*, PQresultErrorField, (const PGresult* res, int field), (res, field))
CABLESIM_LIBPQ(int, PQntuples, (const PGresult* res), (res))
CABLESIM_LIBPQ(char*, PQcmdTuples, (PGresult * res), (res))
CABLESIM_LIBPQ(char*, PQgetvalue, (const PGresult* res, int tup, int field), (res, tup, field))
CABLESIM_LIBPQ(int, PQgetlength, (const PGresult* res, int tup, int field), (res, tup, field))
CABLESIM_LIBPQ(int, PQgetisnull, (const PGresult* res, int tup, int field), (res, tup, field))
CABLESIM_LIBPQ(void, PQclear, (PGresult * res), (res))
CABLESIM_LIBPQ(void, PQfreemem, (void* ptr), (ptr))
