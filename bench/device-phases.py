import json,sys
d=json.load(open(sys.argv[1]))
r=d['runs']['cuda-texture']
print('first gen',r.get('first_generation'),'gens',r['generations'],'s/gen',r['seconds_per_generation'],'kernels/gen',r['seconds_in_kernels']/r['generations'])
g=r['per_generation']; n=len(g)
keys=g[0]['device_phase_seconds'].keys()
print('device phases per gen:', {k: round(sum(x['device_phase_seconds'][k] for x in g)/n,4) for k in keys})
print('span/gen', round(sum(x['batch_span_seconds'] for x in g)/n,4), 'host staging', round(sum(x['backend_host_seconds']['staging'] for x in g)/n,4),
 'waiting', round(sum(x['backend_host_seconds']['waiting'] for x in g)/n,4), 'unpack', round(sum(x['backend_host_seconds']['unpacking'] for x in g)/n,4))
print('phases', {k: round(sum(x['phase_seconds'][k] for x in g)/n,4) for k in g[0]['phase_seconds']})
