/*
 * A minimal native FMI 2.0 co-simulation host, as a native tool uses an FMU: dlopen the
 * binary, instantiate, set up, initialise, step, read, terminate, free. No Python in it.
 *
 *   fmi_host SO RESOURCE_URI GUID STEP NSTEPS OUT_VRS [VR=VALUE ...]
 *
 * OUT_VRS: comma-separated Real value references to print after every step; VR=VALUE: Real
 * start values set before initialisation. Prints "t,v1,v2,..." lines with %.17g (every bit
 * of a double), one per step. Exit status: 0 when every call returned fmi2OK or
 * fmi2Warning, else 2 (instantiation) or 3 (a later call), with the failing call on stderr.
 */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void *fmi2Component;
typedef unsigned int fmi2ValueReference;
typedef int fmi2Status; /* fmi2OK = 0, fmi2Warning = 1, ... */
typedef struct {
    void (*logger)(void *, const char *, fmi2Status, const char *, const char *, ...);
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(void *, fmi2Status);
    void *componentEnvironment;
} fmi2CallbackFunctions;

static void logger(void *env, const char *name, fmi2Status status, const char *category,
                   const char *message, ...) {
    (void)env;
    va_list ap;
    va_start(ap, message);
    fprintf(stderr, "[%s|%d|%s] ", name, status, category);
    vfprintf(stderr, message, ap);
    fputc('\n', stderr);
    va_end(ap);
}

static void *sym(void *lib, const char *name) {
    void *f = dlsym(lib, name);
    if (!f) {
        fprintf(stderr, "missing symbol %s\n", name);
        exit(4);
    }
    return f;
}

#define CHECK(call, what) \
    if ((call) > 1) { \
        fprintf(stderr, "%s failed\n", what); \
        return 3; \
    }

int main(int argc, char **argv) {
    if (argc < 7) {
        fprintf(stderr, "usage: %s SO RESOURCE_URI GUID STEP NSTEPS OUT_VRS [VR=VALUE ...]\n",
                argv[0]);
        return 1;
    }
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "dlopen: %s\n", dlerror());
        return 1;
    }
    fmi2Component (*instantiate)(const char *, int, const char *, const char *,
                                 const fmi2CallbackFunctions *, int, int) =
        sym(lib, "fmi2Instantiate");
    fmi2Status (*setup)(fmi2Component, int, double, double, int, double) =
        sym(lib, "fmi2SetupExperiment");
    fmi2Status (*enter)(fmi2Component) = sym(lib, "fmi2EnterInitializationMode");
    fmi2Status (*exit_init)(fmi2Component) = sym(lib, "fmi2ExitInitializationMode");
    fmi2Status (*set_real)(fmi2Component, const fmi2ValueReference *, size_t,
                           const double *) = sym(lib, "fmi2SetReal");
    fmi2Status (*get_real)(fmi2Component, const fmi2ValueReference *, size_t, double *) =
        sym(lib, "fmi2GetReal");
    fmi2Status (*do_step)(fmi2Component, double, double, int) = sym(lib, "fmi2DoStep");
    fmi2Status (*terminate)(fmi2Component) = sym(lib, "fmi2Terminate");
    void (*free_instance)(fmi2Component) = sym(lib, "fmi2FreeInstance");
    const char *(*version)(void) = sym(lib, "fmi2GetVersion");
    if (strcmp(version(), "2.0") != 0) return 4;

    double step = atof(argv[4]);
    long nsteps = atol(argv[5]);
    fmi2ValueReference out[64];
    size_t nout = 0;
    for (char *tok = strtok(argv[6], ","); tok && nout < 64; tok = strtok(NULL, ","))
        out[nout++] = (fmi2ValueReference)strtoul(tok, NULL, 10);

    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c = instantiate("host", 1, argv[3], argv[2], &cb, 0, 1);
    if (!c) {
        fprintf(stderr, "fmi2Instantiate returned NULL\n");
        return 2;
    }
    CHECK(setup(c, 0, 0.0, 0.0, 0, 0.0), "fmi2SetupExperiment");
    CHECK(enter(c), "fmi2EnterInitializationMode");
    for (int i = 7; i < argc; ++i) {
        fmi2ValueReference vr = (fmi2ValueReference)strtoul(argv[i], NULL, 10);
        double value = atof(strchr(argv[i], '=') + 1);
        CHECK(set_real(c, &vr, 1, &value), "fmi2SetReal");
    }
    CHECK(exit_init(c), "fmi2ExitInitializationMode");
    double values[64];
    for (long k = 0; k < nsteps; ++k) {
        double t = k * step;
        CHECK(do_step(c, t, step, 1), "fmi2DoStep");
        CHECK(get_real(c, out, nout, values), "fmi2GetReal");
        printf("%.17g", t + step);
        for (size_t i = 0; i < nout; ++i) printf(",%.17g", values[i]);
        putchar('\n');
    }
    CHECK(terminate(c), "fmi2Terminate");
    free_instance(c);
    return 0;
}
