/*
 * The FMU's native entry point on Linux: a loader in front of PythonFMU's binary.
 *
 * PythonFMU 0.7.0 builds its binary against Python's stable ABI and links no libpython: it
 * borrows the interpreter of the process that loads it. A Python host (FMPy, libcosimpy,
 * ecospy) has one; a native host (fmusim, the ecos CLI, a Modelica tool) has none, and the
 * binary fails to load ("undefined symbol: _Py_NoneStruct"). This loader is what
 * binaries/linux64/<modelIdentifier>.so holds; PythonFMU's binary sits beside it as
 * <modelIdentifier>_pythonfmu.so (build.py puts both there).
 *
 * - fmi2GetVersion and fmi2GetTypesPlatform are answered here.
 * - At the first fmi2Instantiate: if Python is already in the process (Py_IsInitialized
 *   resolves), nothing is loaded. Otherwise a libpython >= 3.10 is looked for, in order:
 *     1. the file named by the environment variable ROTORTD_LIBPYTHON (when it is set,
 *        only that file: an explicit choice is never silently replaced);
 *     2. the build interpreter's libpython, recorded by build.py in
 *        resources/rotortd_libpython.txt;
 *     3. the sonames libpython3.13.so.1.0 ... libpython3.10.so.1.0 (the linker's path);
 *     4. the library of `python3` on PATH (asked with sysconfig).
 *   Each candidate is probed RTLD_LAZY | RTLD_LOCAL and its Py_GetVersion checked; the one
 *   accepted is opened again RTLD_NOW | RTLD_GLOBAL | RTLD_NODELETE, so that Python's own
 *   extension modules (math, _ctypes) resolve their Py* symbols. A rejected probe is
 *   closed; a library in use is never unloaded. Its installation prefix becomes Python's
 *   home (Py_SetPythonHome, unless PYTHONHOME is set), so that it starts on its own
 *   standard library even when PATH holds another Python of the same version.
 * - Then PythonFMU's binary is opened (RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE) and every
 *   fmi2 function is forwarded to it unchanged. Not RTLD_DEEPBIND: its Py* symbols come
 *   from the global scope either way, and deep binding would give it libc's malloc and
 *   libstdc++'s operator new where a host replaces them. PythonFMU's binary never calls
 *   its own fmi2* entry points, and if a host put this loader in the global scope such a
 *   call would only take one more hop through the forwarder below, never loop.
 * - If no usable libpython is found, fmi2Instantiate returns NULL after one message, through
 *   the host's logger and on stderr, that lists what was tried and names ROTORTD_LIBPYTHON.
 *
 * Only FMI 2.0 types are needed; they are declared here (fmi2TypesPlatform.h, "default").
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <pthread.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define EXPORT __attribute__((visibility("default")))

typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char *fmi2String;
typedef char fmi2Byte;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime,
               fmi2Terminated } fmi2StatusKind;
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status,
                                   fmi2String, fmi2String, ...);
typedef struct {
    fmi2CallbackLogger logger;
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

#define ENV_VAR "ROTORTD_LIBPYTHON"
#define RECORD_FILE "rotortd_libpython.txt"
#define SIBLING_SUFFIX "_pythonfmu.so"
#define MIN_MINOR 10
#define REPORT_MAX 4096

/* ------------------------------------------------------------------ the forwarded table */

/* X(name, return type, parameter list, argument list, value when not loaded) */
#define FMI2_FORWARDED(X) \
    X(fmi2SetDebugLogging, fmi2Status, \
      (fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[]), (c, on, n, cat), \
      fmi2Error) \
    X(fmi2SetupExperiment, fmi2Status, \
      (fmi2Component c, fmi2Boolean tolDef, fmi2Real tol, fmi2Real t0, fmi2Boolean stopDef, \
       fmi2Real t1), (c, tolDef, tol, t0, stopDef, t1), fmi2Error) \
    X(fmi2EnterInitializationMode, fmi2Status, (fmi2Component c), (c), fmi2Error) \
    X(fmi2ExitInitializationMode, fmi2Status, (fmi2Component c), (c), fmi2Error) \
    X(fmi2Terminate, fmi2Status, (fmi2Component c), (c), fmi2Error) \
    X(fmi2Reset, fmi2Status, (fmi2Component c), (c), fmi2Error) \
    X(fmi2GetReal, fmi2Status, \
      (fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[]), \
      (c, vr, n, v), fmi2Error) \
    X(fmi2GetInteger, fmi2Status, \
      (fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]), \
      (c, vr, n, v), fmi2Error) \
    X(fmi2GetBoolean, fmi2Status, \
      (fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]), \
      (c, vr, n, v), fmi2Error) \
    X(fmi2GetString, fmi2Status, \
      (fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]), \
      (c, vr, n, v), fmi2Error) \
    X(fmi2SetReal, fmi2Status, \
      (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[]), \
      (c, vr, n, v), fmi2Error) \
    X(fmi2SetInteger, fmi2Status, \
      (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]), \
      (c, vr, n, v), fmi2Error) \
    X(fmi2SetBoolean, fmi2Status, \
      (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]), \
      (c, vr, n, v), fmi2Error) \
    X(fmi2SetString, fmi2Status, \
      (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]), \
      (c, vr, n, v), fmi2Error) \
    X(fmi2GetFMUstate, fmi2Status, (fmi2Component c, fmi2FMUstate *s), (c, s), fmi2Error) \
    X(fmi2SetFMUstate, fmi2Status, (fmi2Component c, fmi2FMUstate s), (c, s), fmi2Error) \
    X(fmi2FreeFMUstate, fmi2Status, (fmi2Component c, fmi2FMUstate *s), (c, s), fmi2Error) \
    X(fmi2SerializedFMUstateSize, fmi2Status, (fmi2Component c, fmi2FMUstate s, size_t *n), \
      (c, s, n), fmi2Error) \
    X(fmi2SerializeFMUstate, fmi2Status, \
      (fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n), (c, s, b, n), fmi2Error) \
    X(fmi2DeSerializeFMUstate, fmi2Status, \
      (fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s), (c, b, n, s), \
      fmi2Error) \
    X(fmi2GetDirectionalDerivative, fmi2Status, \
      (fmi2Component c, const fmi2ValueReference u[], size_t nu, \
       const fmi2ValueReference z[], size_t nz, const fmi2Real dv[], fmi2Real dz[]), \
      (c, u, nu, z, nz, dv, dz), fmi2Error) \
    X(fmi2SetRealInputDerivatives, fmi2Status, \
      (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer order[], \
       const fmi2Real v[]), (c, vr, n, order, v), fmi2Error) \
    X(fmi2GetRealOutputDerivatives, fmi2Status, \
      (fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer order[], \
       fmi2Real v[]), (c, vr, n, order, v), fmi2Error) \
    X(fmi2DoStep, fmi2Status, \
      (fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noPrior), (c, t, h, noPrior), \
      fmi2Error) \
    X(fmi2CancelStep, fmi2Status, (fmi2Component c), (c), fmi2Error) \
    X(fmi2GetStatus, fmi2Status, (fmi2Component c, const fmi2StatusKind k, fmi2Status *v), \
      (c, k, v), fmi2Error) \
    X(fmi2GetRealStatus, fmi2Status, (fmi2Component c, const fmi2StatusKind k, fmi2Real *v), \
      (c, k, v), fmi2Error) \
    X(fmi2GetIntegerStatus, fmi2Status, \
      (fmi2Component c, const fmi2StatusKind k, fmi2Integer *v), (c, k, v), fmi2Error) \
    X(fmi2GetBooleanStatus, fmi2Status, \
      (fmi2Component c, const fmi2StatusKind k, fmi2Boolean *v), (c, k, v), fmi2Error) \
    X(fmi2GetStringStatus, fmi2Status, \
      (fmi2Component c, const fmi2StatusKind k, fmi2String *v), (c, k, v), fmi2Error)

typedef fmi2Component (*instantiate_fn)(fmi2String, fmi2Type, fmi2String, fmi2String,
                                        const fmi2CallbackFunctions *, fmi2Boolean,
                                        fmi2Boolean);

static struct {
    instantiate_fn fmi2Instantiate;
    void (*fmi2FreeInstance)(fmi2Component);
#define POINTER(name, ret, params, args, dflt) ret(*name) params;
    FMI2_FORWARDED(POINTER)
#undef POINTER
} impl;

static pthread_mutex_t load_lock = PTHREAD_MUTEX_INITIALIZER;
static int loaded; /* 1: impl filled; -1: failed for good (the reason is in failure) */
static char failure[REPORT_MAX];

/* ------------------------------------------------------------------ text helpers */

static void append(char *buf, const char *fmt, ...) {
    size_t used = strlen(buf);
    if (used + 1 >= REPORT_MAX) return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf + used, REPORT_MAX - used, fmt, ap);
    va_end(ap);
}

/* The directory of a "file:" URI (file:///a/b, file:/a/b, file://localhost/a/b), with
   %XX decoded; 0 if the URI is not a local file URI. */
static int uri_to_path(const char *uri, char *out, size_t size) {
    const char *p;
    if (!uri || strncmp(uri, "file:", 5) != 0) return 0;
    p = uri + 5;
    if (strncmp(p, "//localhost/", 12) == 0) p += 11;
    else if (strncmp(p, "///", 3) == 0) p += 2;
    else if (strncmp(p, "//", 2) == 0) return 0; /* a remote host */
    size_t n = 0;
    for (; *p && n + 1 < size; ++p) {
        if (p[0] == '%' && p[1] && p[2]) {
            char hex[3] = {p[1], p[2], 0};
            out[n++] = (char)strtol(hex, NULL, 16);
            p += 2;
        } else {
            out[n++] = *p;
        }
    }
    out[n] = 0;
    return n > 0;
}

/* This loader's own file, from the dynamic linker. */
static int own_path(char *out, size_t size) {
    Dl_info info;
    if (!dladdr((void *)&own_path, &info) || !info.dli_fname) return 0;
    snprintf(out, size, "%s", info.dli_fname);
    return 1;
}

/* ------------------------------------------------------------------ finding libpython */

/* The installation prefix of a libpython 3.<minor> file: the nearest folder above it that
   holds lib/python3.<minor>/os.py (a pyenv or /opt build: <prefix>/lib/libpython...;
   Debian: /usr/lib/x86_64-linux-gnu/libpython... under /usr). 0 if there is none. */
static int library_prefix(const char *path, int minor, char *out, size_t size) {
    char dir[REPORT_MAX], probe[REPORT_MAX + 64];
    if (!realpath(path, dir)) return 0;
    for (char *slash = strrchr(dir, '/'); slash; slash = strrchr(dir, '/')) {
        *slash = 0; /* one folder up */
        snprintf(probe, sizeof probe, "%s/lib/python3.%d/os.py", dir, minor);
        if (access(probe, R_OK) == 0) {
            snprintf(out, size, "%s", *dir ? dir : "/");
            return 1;
        }
    }
    return 0;
}

/* Python computes its prefix from the program name "python3" looked up on PATH, so a host
   whose PATH holds another installation of the same version (a distribution's python3
   beside a pyenv one) would start it on that installation's standard library. The library's
   own prefix is set as Python's home instead (unless the user set PYTHONHOME). */
static void set_python_home(void *lib, const char *path, int minor) {
    static char home[REPORT_MAX];
    if (getenv("PYTHONHOME") || !library_prefix(path, minor, home, sizeof home)) return;
    void *(*decode)(const char *, size_t *) =
        (void *(*)(const char *, size_t *))dlsym(lib, "Py_DecodeLocale");
    void (*set_home)(const void *) = (void (*)(const void *))dlsym(lib, "Py_SetPythonHome");
    if (decode && set_home) {
        void *wide = decode(home, NULL); /* kept for the process's life, as Python needs */
        if (wide) set_home(wide);
    }
}

/* Probe one candidate: 1 if it is a libpython >= 3.MIN_MINOR, now loaded for good into the
   global scope (its home set); otherwise 0 with the reason appended to the report. */
static int try_libpython(const char *what, const char *path, char *report) {
    void *probe = dlopen(path, RTLD_LAZY | RTLD_LOCAL);
    if (!probe) {
        const char *err = dlerror();
        append(report, "\n  %s: %s: %s", what, path, err ? err : "cannot be opened");
        return 0;
    }
    const char *(*version)(void) = (const char *(*)(void))dlsym(probe, "Py_GetVersion");
    int major = 0, minor = 0;
    if (!version || sscanf(version(), "%d.%d", &major, &minor) != 2) {
        append(report, "\n  %s: %s: not a libpython (no Py_GetVersion)", what, path);
        dlclose(probe);
        return 0;
    }
    if (major != 3 || minor < MIN_MINOR) {
        append(report, "\n  %s: %s: Python %d.%d, need 3.%d or newer", what, path, major,
               minor, MIN_MINOR);
        dlclose(probe);
        return 0;
    }
    void *global = dlopen(path, RTLD_NOW | RTLD_GLOBAL | RTLD_NODELETE);
    if (!global) {
        const char *err = dlerror();
        append(report, "\n  %s: %s: %s", what, path, err ? err : "cannot be opened globally");
        dlclose(probe);
        return 0;
    }
    set_python_home(global, path, minor);
    return 1; /* the probe's reference stays: nothing in use is ever unloaded */
}

/* 1: found; 0: not set, search on; -1: set but unusable (an explicit choice is not
   silently replaced by another library). */
static int from_environment(char *report) {
    const char *path = getenv(ENV_VAR);
    if (!path || !*path) {
        append(report, "\n  %s: not set", ENV_VAR);
        return 0;
    }
    return try_libpython(ENV_VAR, path, report) ? 1 : -1;
}

static int from_record(const char *resources, char *report) {
    char file[REPORT_MAX], path[REPORT_MAX];
    if (!resources) {
        append(report, "\n  the build's record: no resource location given by the host");
        return 0;
    }
    snprintf(file, sizeof file, "%s/%s", resources, RECORD_FILE);
    FILE *fh = fopen(file, "r");
    if (!fh) {
        append(report, "\n  the build's record: %s: cannot be read", file);
        return 0;
    }
    int ok = fgets(path, sizeof path, fh) != NULL;
    fclose(fh);
    path[strcspn(path, "\r\n")] = 0;
    if (!ok || !*path) {
        append(report, "\n  the build's record: %s: empty", file);
        return 0;
    }
    return try_libpython("the build interpreter's library", path, report);
}

static int from_sonames(char *report) {
    char soname[64];
    for (int minor = 13; minor >= MIN_MINOR; --minor) {
        snprintf(soname, sizeof soname, "libpython3.%d.so.1.0", minor);
        if (try_libpython("soname", soname, report)) return 1;
    }
    return 0;
}

static int from_python_on_path(char *report) {
    static const char *cmd =
        "python3 -c \"import os, sysconfig as s; v = s.get_config_var; "
        "print(os.path.join(v('LIBDIR') or '', v('INSTSONAME') or ''))\" 2>/dev/null";
    char path[REPORT_MAX] = "";
    FILE *pipe = popen(cmd, "r");
    if (pipe) {
        if (!fgets(path, sizeof path, pipe)) path[0] = 0;
        pclose(pipe);
    }
    path[strcspn(path, "\r\n")] = 0;
    if (!*path) {
        append(report, "\n  python3 on PATH: not found, or it names no library");
        return 0;
    }
    return try_libpython("python3 on PATH", path, report);
}

/* 1 when Python's C API is in the process's global scope (already, or loaded now). */
static int ensure_python(const char *resources, char *report) {
    if (dlsym(RTLD_DEFAULT, "Py_IsInitialized")) return 1; /* a Python host */
    int env = from_environment(report);
    if (env != 0) return env > 0;
    return from_record(resources, report) || from_sonames(report) ||
           from_python_on_path(report);
}

/* ------------------------------------------------------------------ the sibling binary */

static int open_sibling(char *report) {
    char self[REPORT_MAX], path[REPORT_MAX];
    if (!own_path(self, sizeof self)) {
        append(report, "cannot find this loader's own file (dladdr)");
        return 0;
    }
    size_t n = strlen(self);
    if (n > 3 && strcmp(self + n - 3, ".so") == 0) self[n - 3] = 0;
    snprintf(path, sizeof path, "%s%s", self, SIBLING_SUFFIX);
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
    if (!h) {
        const char *err = dlerror();
        append(report, "cannot open PythonFMU's binary %s: %s", path, err ? err : "?");
        return 0;
    }
    impl.fmi2Instantiate = (instantiate_fn)dlsym(h, "fmi2Instantiate");
    impl.fmi2FreeInstance = (void (*)(fmi2Component))dlsym(h, "fmi2FreeInstance");
#define RESOLVE(name, ret, params, args, dflt) impl.name = (ret(*) params)dlsym(h, #name);
    FMI2_FORWARDED(RESOLVE)
#undef RESOLVE
    if (!impl.fmi2Instantiate || !impl.fmi2FreeInstance || !impl.fmi2DoStep) {
        append(report, "PythonFMU's binary %s lacks the FMI 2.0 functions", path);
        return 0;
    }
    return 1;
}

static int load(const char *resources) {
    pthread_mutex_lock(&load_lock);
    if (loaded == 0) {
        char report[REPORT_MAX] = "";
        if (!ensure_python(resources, report)) {
            snprintf(failure, sizeof failure,
                     "no usable Python shared library (3.%d or newer) was found for this "
                     "Python FMU; tried:%s\nSet %s to the path of a libpython3.X.so "
                     "(for example the one `python3 -c \"import sysconfig; "
                     "print(sysconfig.get_config_var('LIBDIR'))\"` names)",
                     MIN_MINOR, report, ENV_VAR);
            loaded = -1;
        } else if (!open_sibling(report)) {
            snprintf(failure, sizeof failure, "%s", report);
            loaded = -1;
        } else {
            loaded = 1;
        }
    }
    int ok = loaded == 1;
    pthread_mutex_unlock(&load_lock);
    return ok;
}

/* ------------------------------------------------------------------ the FMI 2.0 API */

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }

EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

EXPORT fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType,
                                     fmi2String fmuGUID, fmi2String fmuResourceLocation,
                                     const fmi2CallbackFunctions *functions,
                                     fmi2Boolean visible, fmi2Boolean loggingOn) {
    char resources[REPORT_MAX];
    int have = uri_to_path(fmuResourceLocation, resources, sizeof resources);
    if (!load(have ? resources : NULL)) {
        const char *name = instanceName ? instanceName : "?";
        fprintf(stderr, "%s: error: %s\n", name, failure);
        fflush(stderr);
        if (functions && functions->logger)
            functions->logger(functions->componentEnvironment, name, fmi2Error, "error",
                              "%s", failure);
        return NULL;
    }
    return impl.fmi2Instantiate(instanceName, fmuType, fmuGUID, fmuResourceLocation,
                                functions, visible, loggingOn);
}

EXPORT void fmi2FreeInstance(fmi2Component c) {
    if (impl.fmi2FreeInstance) impl.fmi2FreeInstance(c);
}

#define FORWARD(name, ret, params, args, dflt) \
    EXPORT ret name params { \
        if (!impl.name) return dflt; \
        return impl.name args; \
    }
FMI2_FORWARDED(FORWARD)
#undef FORWARD
