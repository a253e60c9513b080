#!/bin/sh
# pairs.sh OMBRA N DIR (SIZE=WxH, default 32x24): N rounds of two renders racing to one --out/--mask pair (sm
# with two biases: as long as each other, different images and masks); after each
# round the pair on disk must be one run's image beside the same run's mask
# (platform/out.c locks the directory around a run's renames). make check runs 100
# rounds; before the lock, 1,000 rounds at 160x120 left 7 mixed pairs.
set -u
OMBRA=$1; N=$2; dir=$3
mkdir -p "$dir"
for m in 6e-5 1; do
    "$OMBRA" render --quiet --size ${SIZE:-32x24} --bias $m --threads 1 --out "$dir/ref-$m.ppm" --mask "$dir/ref-$m.pgm" || exit 1
done
cmp -s "$dir/ref-6e-5.pgm" "$dir/ref-1.pgm" && { echo "pairs: the two biases draw one mask"; exit 1; }
mixed=0
i=0
while [ $i -lt "$N" ]; do
    "$OMBRA" render --quiet --size ${SIZE:-32x24} --bias 6e-5 --threads 1 --out "$dir/o.ppm" --mask "$dir/o.pgm" &
    "$OMBRA" render --quiet --size ${SIZE:-32x24} --bias 1 --threads 1 --out "$dir/o.ppm" --mask "$dir/o.pgm" &
    wait
    ok=0
    for m in 6e-5 1; do
        cmp -s "$dir/o.ppm" "$dir/ref-$m.ppm" && cmp -s "$dir/o.pgm" "$dir/ref-$m.pgm" && ok=1
    done
    [ $ok -eq 1 ] || mixed=$((mixed + 1))
    i=$((i + 1))
done
echo "pairs: $N rounds of two racing renders, $mixed mixed pairs"
[ $mixed -eq 0 ]
