#!/usr/bin/env python3
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Summary of one run of a `morea benchmark` JSON (BACKEND, or the first): seconds per
generation, and per generation the device phases (device_phase_seconds), the
batch span, the backend's host time and the optimiser's phases.
Usage: tools/profiling/device-phases.py BENCHMARK_JSON [BACKEND]"""
import json,sys
d=json.load(open(sys.argv[1]))
r=d['runs'][sys.argv[2]] if len(sys.argv) > 2 else next(iter(d['runs'].values()))
print('first gen',r.get('first_generation'),'gens',r['generations'],'s/gen',r['seconds_per_generation'],'kernels/gen',r['seconds_in_kernels']/r['generations'])
g=r['per_generation']; n=len(g)
keys=g[0]['device_phase_seconds'].keys()
print('device phases per gen:', {k: round(sum(x['device_phase_seconds'][k] for x in g)/n,4) for k in keys})
print('span/gen', round(sum(x['batch_span_seconds'] for x in g)/n,4), 'host staging', round(sum(x['backend_host_seconds']['staging'] for x in g)/n,4),
 'waiting', round(sum(x['backend_host_seconds']['waiting'] for x in g)/n,4), 'unpack', round(sum(x['backend_host_seconds']['unpacking'] for x in g)/n,4))
print('phases', {k: round(sum(x['phase_seconds'][k] for x in g)/n,4) for k in g[0]['phase_seconds']})
