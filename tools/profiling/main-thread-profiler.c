// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/* A sampling profiler of one program's main thread in wall-clock time, for
 * machines without perf or gdb (the GPU machines bench/run-device-benchmark.sh
 * runs on). Loaded with LD_PRELOAD; inactive unless MOREA_PROFILE names the
 * file to write. A POSIX timer on CLOCK_MONOTONIC signals the main thread
 * MOREA_PROFILE_HZ times a second (default 500) whether it computes or
 * waits, so the samples show where the main thread's wall time goes,
 * waits on the device included. Each sample's call stack (return
 * addresses) is kept in memory and written at exit with /proc/self/maps;
 * tools/profiling/profile-report.py names the functions. Each sample's "s" line
 * follows a "t" line with its CLOCK_MONOTONIC time in nanoseconds (the clock
 * of device-timeline.c's records).
 *   cc -O2 -shared -fPIC -o main-thread-profiler.so main-thread-profiler.c
 */
#define _GNU_SOURCE
#include <errno.h>
#include <execinfo.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

enum
{
  MaxFrames = 48,
  MaxSamples = 400000
};

static void ** g_Frames;
static unsigned char * g_Depths;
static unsigned long long * g_Times;
static volatile long g_Count;
static long g_Dropped;
static timer_t g_Timer;
static int g_Active;

static void
OnTick(int signal)
{
  (void)signal;
  const long i = g_Count;
  if (i >= MaxSamples)
  {
    ++g_Dropped;
    return;
  }
  const int saved = errno;
  struct timespec now;
  clock_gettime(CLOCK_MONOTONIC, &now);
  g_Times[i] = (unsigned long long)now.tv_sec * 1000000000ull + (unsigned long long)now.tv_nsec;
  g_Depths[i] = (unsigned char)backtrace(g_Frames + (size_t)i * MaxFrames, MaxFrames);
  g_Count = i + 1;
  errno = saved;
}

__attribute__((constructor)) static void
StartProfile(void)
{
  const char * path = getenv("MOREA_PROFILE");
  if (!path || !*path)
    return;
  const char * hzText = getenv("MOREA_PROFILE_HZ");
  const long   hz = hzText ? atol(hzText) : 500;
  g_Frames = malloc(sizeof(void *) * (size_t)MaxFrames * MaxSamples);
  g_Depths = malloc(MaxSamples);
  g_Times = malloc(sizeof(unsigned long long) * MaxSamples);
  if (!g_Frames || !g_Depths || !g_Times || hz <= 0 || hz > 100000)
  {
    fprintf(stderr, "main-thread-profiler: cannot start (memory or MOREA_PROFILE_HZ)\n");
    return;
  }
  void * warm[4];
  backtrace(warm, 4); // loads the unwinder now, not in the signal handler
  struct sigaction action;
  memset(&action, 0, sizeof action);
  action.sa_handler = OnTick;
  action.sa_flags = SA_RESTART;
  sigemptyset(&action.sa_mask);
  sigaction(SIGPROF, &action, NULL);
  struct sigevent event;
  memset(&event, 0, sizeof event);
  event.sigev_notify = SIGEV_THREAD_ID;
  event.sigev_signo = SIGPROF;
  event._sigev_un._tid = (pid_t)syscall(SYS_gettid);
  if (timer_create(CLOCK_MONOTONIC, &event, &g_Timer) != 0)
  {
    perror("main-thread-profiler: timer_create");
    return;
  }
  struct itimerspec period;
  memset(&period, 0, sizeof period);
  period.it_interval.tv_nsec = 1000000000L / hz;
  period.it_value = period.it_interval;
  timer_settime(g_Timer, 0, &period, NULL);
  g_Active = 1;
}

__attribute__((destructor)) static void
WriteProfile(void)
{
  if (!g_Active)
    return;
  g_Active = 0;
  timer_delete(g_Timer);
  FILE * out = fopen(getenv("MOREA_PROFILE"), "w");
  if (!out)
  {
    perror("main-thread-profiler: output");
    return;
  }
  fprintf(out, "# samples %ld dropped %ld hz %s\n", g_Count, g_Dropped,
          getenv("MOREA_PROFILE_HZ") ? getenv("MOREA_PROFILE_HZ") : "500");
  for (long i = 0; i < g_Count; ++i)
  {
    fprintf(out, "t %llu\n", g_Times[i]);
    fputc('s', out);
    for (int k = 0; k < g_Depths[i]; ++k)
      fprintf(out, " %lx", (unsigned long)g_Frames[(size_t)i * MaxFrames + k]);
    fputc('\n', out);
  }
  FILE * maps = fopen("/proc/self/maps", "r");
  char   line[4096];
  while (maps && fgets(line, sizeof line, maps))
    fprintf(out, "m %s", line);
  if (maps)
    fclose(maps);
  fclose(out);
}
