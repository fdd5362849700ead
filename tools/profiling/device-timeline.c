// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/* A timeline of one program's device work and CUDA runtime calls, for GPU
 * machines without Nsight Systems (those bench/run-device-benchmark.sh runs
 * on). Loaded with LD_PRELOAD; inactive unless MOREA_TIMELINE names the file
 * to write. CUPTI's activity records (kernels, copies, sets, runtime calls)
 * are stamped with CLOCK_MONOTONIC, the clock main-thread-profiler.c stamps
 * its samples with, so that tools/profiling/device-gaps.py can tell what the
 * main thread did while the device stood idle. One line per record:
 *   k START END STREAM CORRELATION NAME        a kernel
 *   c START END STREAM CORRELATION KIND BYTES  a copy (CUPTI's copy kind)
 *   z START END STREAM CORRELATION             a memory set
 *   a START END THREAD CORRELATION NAME        a runtime call (the one that
 *                                              queued the work of that id)
 * Records are written when CUPTI hands over a buffer and when the context
 * is destroyed (before the runtime's own teardown at exit).
 *   cc -O2 -shared -fPIC -o device-timeline.so device-timeline.c -I CUDA/include -L CUDA/lib -lcupti
 */
#define _GNU_SOURCE
#include <cupti.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum
{
  BufferBytes = 8 << 20
};

static FILE *          g_Out;
static pthread_mutex_t g_Lock = PTHREAD_MUTEX_INITIALIZER;
static int             g_Active;

static uint64_t CUPTIAPI
MonotonicNanoseconds(void)
{
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (uint64_t)t.tv_sec * 1000000000ull + (uint64_t)t.tv_nsec;
}

static void CUPTIAPI
BufferRequested(uint8_t ** buffer, size_t * size, size_t * maxRecords)
{
  *buffer = aligned_alloc(8, BufferBytes);
  *size = *buffer ? BufferBytes : 0;
  *maxRecords = 0;
}

static void CUPTIAPI
BufferCompleted(CUcontext context, uint32_t stream, uint8_t * buffer, size_t size, size_t valid)
{
  (void)context;
  (void)stream;
  (void)size;
  CUpti_Activity * record = NULL;
  pthread_mutex_lock(&g_Lock);
  while (g_Out && cuptiActivityGetNextRecord(buffer, valid, &record) == CUPTI_SUCCESS)
  {
    switch (record->kind)
    {
      case CUPTI_ACTIVITY_KIND_CONCURRENT_KERNEL:
      case CUPTI_ACTIVITY_KIND_KERNEL:
      {
        const CUpti_ActivityKernel10 * k = (const CUpti_ActivityKernel10 *)record;
        fprintf(g_Out, "k %llu %llu %u %u %s\n", (unsigned long long)k->start, (unsigned long long)k->end, k->streamId,
                k->correlationId, k->name ? k->name : "?");
        break;
      }
      case CUPTI_ACTIVITY_KIND_MEMCPY:
      {
        const CUpti_ActivityMemcpy6 * m = (const CUpti_ActivityMemcpy6 *)record;
        fprintf(g_Out, "c %llu %llu %u %u %u %llu\n", (unsigned long long)m->start, (unsigned long long)m->end,
                m->streamId, m->correlationId, (unsigned)m->copyKind, (unsigned long long)m->bytes);
        break;
      }
      case CUPTI_ACTIVITY_KIND_MEMSET:
      {
        const CUpti_ActivityMemset4 * m = (const CUpti_ActivityMemset4 *)record;
        fprintf(g_Out, "z %llu %llu %u %u\n", (unsigned long long)m->start, (unsigned long long)m->end, m->streamId,
                m->correlationId);
        break;
      }
      case CUPTI_ACTIVITY_KIND_RUNTIME:
      {
        const CUpti_ActivityAPI * a = (const CUpti_ActivityAPI *)record;
        const char *              name = NULL;
        if (cuptiGetCallbackName(CUPTI_CB_DOMAIN_RUNTIME_API, a->cbid, &name) != CUPTI_SUCCESS || !name)
          name = "?";
        fprintf(g_Out, "a %llu %llu %u %u %s\n", (unsigned long long)a->start, (unsigned long long)a->end, a->threadId,
                a->correlationId, name);
        break;
      }
      default:
        break;
    }
  }
  pthread_mutex_unlock(&g_Lock);
  free(buffer);
}

static void
Flush(void)
{
  if (!g_Active)
    return;
  cuptiActivityFlushAll(1);
  pthread_mutex_lock(&g_Lock);
  if (g_Out)
    fflush(g_Out);
  pthread_mutex_unlock(&g_Lock);
}

/* The runtime destroys its context at exit, after which CUPTI's buffers
 * can no longer be flushed: flush when that begins. */
static void CUPTIAPI
OnResource(void * data, CUpti_CallbackDomain domain, CUpti_CallbackId id, const void * info)
{
  (void)data;
  (void)info;
  if (domain == CUPTI_CB_DOMAIN_RESOURCE && id == CUPTI_CBID_RESOURCE_CONTEXT_DESTROY_STARTING)
    Flush();
}

static int
Checked(CUptiResult result, const char * what)
{
  if (result == CUPTI_SUCCESS)
    return 1;
  const char * text = NULL;
  cuptiGetResultString(result, &text);
  fprintf(stderr, "device-timeline: %s: %s\n", what, text ? text : "?");
  return 0;
}

__attribute__((constructor)) static void
StartTimeline(void)
{
  const char * path = getenv("MOREA_TIMELINE");
  if (!path || !*path)
    return;
  g_Out = fopen(path, "w");
  if (!g_Out)
  {
    perror("device-timeline: output");
    return;
  }
  CUpti_SubscriberHandle subscriber;
  if (!Checked(cuptiActivityRegisterTimestampCallback(MonotonicNanoseconds), "the clock") ||
      !Checked(cuptiActivityRegisterCallbacks(BufferRequested, BufferCompleted), "buffers") ||
      !Checked(cuptiSubscribe(&subscriber, (CUpti_CallbackFunc)OnResource, NULL), "subscribing") ||
      !Checked(cuptiEnableCallback(1, subscriber, CUPTI_CB_DOMAIN_RESOURCE, CUPTI_CBID_RESOURCE_CONTEXT_DESTROY_STARTING),
               "the context callback") ||
      !Checked(cuptiActivityEnable(CUPTI_ACTIVITY_KIND_CONCURRENT_KERNEL), "kernels") ||
      !Checked(cuptiActivityEnable(CUPTI_ACTIVITY_KIND_MEMCPY), "copies") ||
      !Checked(cuptiActivityEnable(CUPTI_ACTIVITY_KIND_MEMSET), "sets") ||
      !Checked(cuptiActivityEnable(CUPTI_ACTIVITY_KIND_RUNTIME), "runtime calls"))
    return;
  g_Active = 1;
  atexit(Flush);
}

__attribute__((destructor)) static void
EndTimeline(void)
{
  Flush();
  g_Active = 0;
  pthread_mutex_lock(&g_Lock);
  if (g_Out)
    fclose(g_Out);
  g_Out = NULL;
  pthread_mutex_unlock(&g_Lock);
}
