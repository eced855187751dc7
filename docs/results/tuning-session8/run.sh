#!/bin/bash
# usage: run.sh NAME pin_height thin_t [thick_t] [from to step]
name=$1; ph=$2; tt=$3; kt=${4:-0.010}; from=${5:-0.2}; to=${6:-0.8}; step=${7:-0.05}
cd "$(git rev-parse --show-toplevel)"; mkdir -p out/tuning
sc=out/tuning/$name.toml
python3 - "$ph" "$tt" "$kt" > $sc <<'PY'
import sys,re
ph,tt,kt=sys.argv[1:4]
s=open('scenes/pin-on-disc.toml').read()
def sect(s,name,key,val):
    a=s.index(f"[{name}]"); b=s.index("\n[",a+1) if "\n[" in s[a+1:] else len(s)
    body=re.sub(rf"^{key} = .*$",f"{key} = {val}",s[a:b],count=1,flags=re.M)
    return s[:a]+body+s[b:]
s=sect(s,"pin","height_m",ph); s=sect(s,"thin_plate","thickness_m",tt); s=sect(s,"thick_plate","thickness_m",kt)
s=s.replace('name = "pin-on-disc"','name = "scan"')
print(s)
PY
start=$(date +%s)
./target/release/squeal sweep mu $sc --from $from --to $to --step $step --basis cms --band 0:5000 --out out/tuning/out-$name > out/tuning/$name.log 2>&1
echo "$name ph=$ph tt=$tt kt=$kt: $(( $(date +%s) - start )) s" >> out/tuning/times.txt
/usr/bin/python3 -c "
import json; s=json.load(open('out/tuning/out-$name/summary.json'))
for c in s['couplings']: print('$name', round(c['freq_hz']), c['mu_from'], c['mu_to'], '%.2e'%c['max_dvr'], c.get('partners'))
" >> out/tuning/couplings.txt 2>&1
