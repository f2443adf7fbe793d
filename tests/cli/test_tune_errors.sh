#!/bin/sh
# `godrays sweep` and `godrays tune` with bad parameter specs or options: exit 2, exactly one
# stderr line that names the flag and the reason, nothing on stdout, nothing rendered
# (these are all rejected before any GL or ground-truth work).
. "$(dirname "$0")/lib.sh"
small_scene "$dir/s.json" 32 18
s="$dir/s.json"
o="$dir/o"
# sweep: unknown key, empty range, non-numeric, bad count, enum/bool, malformed
expect 2 "--param shafts.nope: unknown shafts setting" sweep "$s" -o "$o" --param shafts.nope=0:1:4
expect 2 "unknown parameter" sweep "$s" -o "$o" --param medium.g=0:1:4
expect 2 "empty range" sweep "$s" -o "$o" --param shafts.K=1.2:0.4:16
expect 2 "empty range" sweep "$s" -o "$o" --param shafts.K=0.5:0.5:4
expect 2 "LO and HI must be finite numbers" sweep "$s" -o "$o" --param shafts.K=abc:1:4
expect 2 "COUNT must be an integer" sweep "$s" -o "$o" --param shafts.K=0.4:1.2:x
expect 2 "COUNT must be in" sweep "$s" -o "$o" --param shafts.K=0.4:1.2:0
expect 2 "not a numeric setting" sweep "$s" -o "$o" --param shafts.target_format=0:1:2
expect 2 "not a numeric setting" sweep "$s" -o "$o" --param shafts.caps=0:1:2
expect 2 "expected TECHNIQUE.KEY=LO:HI:COUNT" sweep "$s" -o "$o" --param shafts.K
expect 2 "shafts.K" sweep "$s" -o "$o" --param shafts.K=-1:1:3
expect 2 "at most two axes" sweep "$s" -o "$o" --param shafts.K=0.4:1:2 --param shafts.g=0:0.5:2 --param shafts.bias=0:1:2
expect 2 "swept twice" sweep "$s" -o "$o" --param shafts.K=0.4:1:2 --param shafts.K=0.5:1:2
expect 2 "no --param" sweep "$s" -o "$o"
expect 2 "--metric psnr: unknown metric" sweep "$s" -o "$o" --param shafts.K=0.4:1:2 --metric psnr
expect 2 "--frames" sweep "$s" -o "$o" --param shafts.K=0.4:1:2 --frames 5:1:1
expect 2 "--view" sweep "$s" -o "$o" --param shafts.K=0.4:1:2 --view 10
expect 2 "no scene" sweep --param shafts.K=0.4:1:2
expect 2 "shafts.K" sweep "$s" -o "$o" --param shafts.K=0.4:1:2 --set shafts.K=0
# tune
expect 2 "--params shafts.nope: unknown shafts setting" tune "$s" -o "$o" --params shafts.nope
expect 2 "integer setting" tune "$s" -o "$o" --params shafts.K,shafts.N
expect 2 "not a numeric setting" tune "$s" -o "$o" --params shafts.target_format
expect 2 "empty parameter name" tune "$s" -o "$o" --params shafts.K,,shafts.g
expect 2 "given twice" tune "$s" -o "$o" --params shafts.K,shafts.K
expect 2 "--bounds shafts.K=2:1: empty range" tune "$s" -o "$o" --params shafts.K --bounds shafts.K=2:1
expect 2 "LO and HI must be finite numbers" tune "$s" -o "$o" --params shafts.K --bounds shafts.K=a:b
expect 2 "not among the --params" tune "$s" -o "$o" --params shafts.K --bounds shafts.g=0:0.5
expect 2 "--start" tune "$s" -o "$o" --params shafts.K --start shafts.K=x
expect 2 "--starts" tune "$s" -o "$o" --params shafts.K --starts 0
# without --params the technique's default list is tuned (docs/tuning.md); an unknown technique
# is still refused before any work
expect 2 "--technique no_such_technique: unknown technique" tune "$s" -o "$o" --technique no_such_technique
expect 2 "--coarse" tune "$s" -o "$o" --params shafts.K --coarse x
expect 2 "--seed" tune "$s" -o "$o" --params shafts.K --seed -1
expect 2 "--method" tune "$s" -o "$o" --params shafts.K --method simplex
# techniques by name
expect 2 "--technique no_such_technique: unknown technique 'no_such_technique'" tune "$s" -o "$o" --params shafts.K --technique no_such_technique
expect 2 "--technique no_such_technique: unknown technique" sweep "$s" -o "$o" --param shafts.K=0.5:1:3 --technique no_such_technique
expect 2 "--techniques shafts,nope: unknown technique 'nope'" pareto "$s" -o "$o" --techniques shafts,nope
expect 2 "$dir/no_such_dir" tune "$s" -o "$o" --params shafts.K --technique-dir "$dir/no_such_dir"
# pareto
expect 2 "--size" pareto "$s" -o "$o" --size 0x5
expect 2 "--repeat" pareto "$s" -o "$o" --repeat 0
[ -e "$o" ] && { echo "FAIL: output folder created by a failing command"; fail=1; }
exit $fail
