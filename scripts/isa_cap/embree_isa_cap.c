/* embree_isa_cap.c: an LD_PRELOAD shim that caps the instruction set of every Embree 3
 * device a process creates.
 *
 * Why it exists (issue 14): the comparison with Mitsuba 3 is asked for on an AVX2-only
 * host, and every host we can reach has AVX-512. tools/mitsuba_speed.py --emulate-isa
 * avx2 stands in for one by capping every component at AVX2 on the AVX-512 host:
 * pathbench's path step (`--isa avx2`), Dr.Jit's LLVM code generation
 * (jit_llvm_set_target), and Embree, through this shim. Embree 3 chooses its kernels
 * from the CPU, and Debian's build reads no config file, but rtcNewDevice(config)
 * accepts `max_isa=avx2`. The shim intercepts rtcNewDevice (Debian's libembree3, used
 * by pathbench) and mitsuba::rtcNewDevice (the Embree that Mitsuba's wheel bundles, its
 * API in namespace mitsuba), appends `,max_isa=$PATHBENCH_EMBREE_MAX_ISA` to the
 * caller's config (max_isa ANDs the enabled ISA, so it caps whatever came before it)
 * and calls the real function. It is an emulation: same caches, clocks and memory.
 *
 * Environment:
 *   PATHBENCH_EMBREE_MAX_ISA   avx2, sse4.2, ... (unset or empty: config passed as is)
 *   PATHBENCH_EMBREE_VERBOSE   appends verbose=N: Embree prints the ISA it enabled
 *   PATHBENCH_EMBREE_CAP_LOG   1: one line on stderr per device, with the config used
 *
 * pathbench_embree_isa_cap_report() (found with dlsym(RTLD_DEFAULT, ...), e.g. ctypes'
 * CDLL(None)) returns JSON: devices created through the shim, the last config, and the
 * last device's native packet widths as Embree answers them (16 only with AVX-512).
 *
 * Build: scripts/isa_cap/build.sh [OUT.so]  (gcc -shared -fPIC ... -ldl; no Embree headers).
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <link.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/types.h>

typedef void *(*new_device_fn)(const char *);
typedef ssize_t (*device_property_fn)(void *, int);

/* The two Embree builds this project meets: Debian's (C API) and Mitsuba's bundled one. */
static const struct api {
  const char *new_device, *device_property, *name;
} kDebian = {"rtcNewDevice", "rtcGetDeviceProperty", "embree"},
  kMitsuba = {"_ZN7mitsuba12rtcNewDeviceEPKc",
              "_ZN7mitsuba20rtcGetDevicePropertyEPNS_11RTCDeviceTyENS_17RTCDevicePropertyE", "mitsuba-embree"};

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static int devices;
static char report[2048] = "{\"devices\": 0}";

struct search {
  const char *symbol;
  void *self, *found;
};

/* A library loaded by dlopen with RTLD_LOCAL (Python extensions, and so Mitsuba's Embree)
 * is not in the scope RTLD_NEXT searches: look in each loaded object instead. */
static int search_object(struct dl_phdr_info *info, size_t size, void *data) {
  (void)size;
  struct search *s = data;
  if (!info->dlpi_name || !*info->dlpi_name) return 0;
  void *h = dlopen(info->dlpi_name, RTLD_LAZY | RTLD_NOLOAD);
  if (!h) return 0;
  void *p = dlsym(h, s->symbol);
  dlclose(h);
  if (p && p != s->self) {
    s->found = p;
    return 1;
  }
  return 0;
}

static void *real_symbol(const char *symbol, void *self) {
  void *p = dlsym(RTLD_NEXT, symbol);
  if (p && p != self) return p;
  struct search s = {symbol, self, NULL};
  dl_iterate_phdr(search_object, &s);
  return s.found;
}

/* Appends ",<key><value>" to buf (no comma when buf is empty; nothing when value is NULL or
 * empty). Returns 0 when it does not fit. */
static int append(char *buf, size_t size, size_t *n, const char *key, const char *value) {
  if (!value || !*value) return 1;
  int k = snprintf(buf + *n, size - *n, "%s%s%s", *n ? "," : "", key, value);
  if (k < 0 || (size_t)k >= size - *n) return 0;
  *n += (size_t)k;
  return 1;
}

static int known_isa(const char *isa) {
  static const char *const names[] = {"sse2", "sse4.2", "avx", "avx2", "avx512"};
  for (size_t i = 0; i < sizeof names / sizeof *names; ++i)
    if (strcasecmp(isa, names[i]) == 0) return 1;
  return 0;
}

static void *capped_new_device(const struct api *api, void *self, const char *config) {
  new_device_fn real = (new_device_fn)real_symbol(api->new_device, self);
  if (!real) {
    fprintf(stderr, "embree_isa_cap: no %s to forward to\n", api->new_device);
    return NULL;
  }
  const char *isa = getenv("PATHBENCH_EMBREE_MAX_ISA");
  const char *verbose = getenv("PATHBENCH_EMBREE_VERBOSE");
  if (isa && *isa && !known_isa(isa)) {  // Embree takes a name it does not know as SSE2, silently
    fprintf(stderr, "embree_isa_cap: PATHBENCH_EMBREE_MAX_ISA=%s is not one of sse2, sse4.2, avx, avx2, avx512\n", isa);
    return NULL;
  }
  char cfg[1024] = "";
  size_t n = 0;
  int ok = append(cfg, sizeof cfg, &n, "", config) && append(cfg, sizeof cfg, &n, "max_isa=", isa) &&
           append(cfg, sizeof cfg, &n, "verbose=", verbose);
  if (!ok) {  // never drop the cap silently
    fprintf(stderr, "embree_isa_cap: config too long: %s\n", config);
    return NULL;
  }
  if (getenv("PATHBENCH_EMBREE_CAP_LOG")) fprintf(stderr, "embree_isa_cap: %s(\"%s\")\n", api->name, cfg);
  void *device = real(cfg);

  char widths[16] = "";
  device_property_fn prop = (device_property_fn)real_symbol(api->device_property, NULL);
  for (int w = 4, p = 32; device && prop && w <= 16; w *= 2, ++p)  // RTC_DEVICE_PROPERTY_NATIVE_RAY4/8/16
    if (prop(device, p)) snprintf(widths + strlen(widths), sizeof widths - strlen(widths), "%s%d", *widths ? ", " : "", w);
  for (char *c = cfg; *c; ++c)
    if (*c == '"' || *c == '\\') *c = '\'';
  pthread_mutex_lock(&lock);
  snprintf(report, sizeof report,
           "{\"devices\": %d, \"library\": \"%s\", \"max_isa\": \"%s\", \"config\": \"%s\", "
           "\"created\": %s, \"native_packet_widths\": [%s]}",
           ++devices, api->name, isa ? isa : "", cfg, device ? "true" : "false", widths);
  pthread_mutex_unlock(&lock);
  return device;
}

void *rtcNewDevice(const char *config) { return capped_new_device(&kDebian, (void *)rtcNewDevice, config); }

void *_ZN7mitsuba12rtcNewDeviceEPKc(const char *config) {
  return capped_new_device(&kMitsuba, (void *)_ZN7mitsuba12rtcNewDeviceEPKc, config);
}

const char *pathbench_embree_isa_cap_report(void) {
  static char copy[sizeof report];
  pthread_mutex_lock(&lock);
  memcpy(copy, report, sizeof copy);
  pthread_mutex_unlock(&lock);
  return copy;
}
