#!/usr/bin/env bash
# Bad traced shoots for kind shoot_traces, RSML and CSV (issue 20): exit 2,
# one message naming the file and line, nothing left behind.
#   RSML without a time function; RSML whose time goes backwards along a
#   root; RSML with a time function short of samples; RSML in pixels (no
#   length unit); CSV naming an unknown parent shoot; seek_light's keys out
#   of range in the model plant's grow config; covariance_at, _rounds and
#   _tolerance out of range.
#
#   bash test_climbing_traces.sh PATH/TO/phytocal
#
# Prints "ok - <case>" / "not ok - <case>: <why>", then "N passed, M failed".

source "$(dirname "${BASH_SOURCE[0]}")/../cli_cases.sh" "$@"
EX="$SCRIPT_DIR/../../measurements/examples/climbing"
cp "$EX/wall.obj" .
cp "$EX/plant.yaml" .

config() { # FILE TRACES [PLANT]
    printf 'name: st\nparameters:\n  growth_rate: {value: 0.2, lower: 0.05, upper: 0.5}\ndatasets:\n  - kind: shoot_traces\n    file: %s\n    plant: %s\n    seeds: 2\n' "$2" "${3:-plant.yaml}" >"$1"
}
bad_case() { # name, config, expected message parts...
    local name=$1 cfg=$2
    shift 2
    rm -rf out
    run fit "$cfg" -o out
    [ "$RC" -eq 2 ] || why "exit $RC, expected 2"
    local e
    for e in "$@"; do
        grep -qF -- "$e" "$T/stderr" || why "message lacks '$e'"
    done
    [ "$(grep -c . "$T/stderr")" -eq 1 ] || why "not one line on stderr"
    [ ! -e out ] || why "left out/ behind"
    finish "$name"
}
rsml() { # FILE UNIT BODY
    printf '<?xml version="1.0"?>\n<rsml>\n<metadata><version>1</version><unit>%s</unit><resolution>1</resolution></metadata>\n<scene><plant id="1">\n%s</plant></scene>\n</rsml>\n' "$2" "$3" >"$1"
}
POLY='<geometry><polyline><point x="0" y="0.03" z="0"/><point x="0" y="0.03" z="0.01"/><point x="0" y="0.03" z="0.02"/></polyline></geometry>'

rsml notime.rsml m "<root id=\"a\">$POLY</root>
"
config notime.yaml notime.rsml
bad_case "RSML without a time function" notime.yaml "notime.rsml:5: root 'a'" "no per-point function named 'time'"

rsml back.rsml m "<root id=\"a\">$POLY
<functions><function name=\"time\" domain=\"polyline\">
<sample>0</sample>
<sample>5</sample>
<sample>3</sample>
</function></functions></root>
"
config back.yaml back.rsml
bad_case "RSML whose time goes backwards" back.yaml "back.rsml:9: root 'a'" "time goes backwards" "3 s, after 5 s"

rsml few.rsml m "<root id=\"a\">$POLY
<functions><function name=\"time\" domain=\"polyline\"><sample>0</sample><sample>5</sample></function></functions></root>
"
config few.yaml few.rsml
bad_case "RSML time function short of samples" few.yaml "few.rsml:6: root 'a'" "2 samples, expected one per polyline point (3)"

rsml pixel.rsml pixel "<root id=\"a\">$POLY
<functions><function name=\"time\" domain=\"polyline\"><sample>0</sample><sample>1</sample><sample>2</sample></function></functions></root>
"
config pixel.yaml pixel.rsml
bad_case "RSML in pixels" pixel.yaml "pixel.rsml: metadata <unit> 'pixel' is not a length"

printf 'time,shoot,x,y,z,parent\n0,a,0,0.03,0,\n1,a,0,0.03,0.01,\n1,b,0,0.03,0.005,nobody\n2,b,0.01,0.03,0.01,nobody\n' >unknown.csv
config unknown.yaml unknown.csv
bad_case "CSV naming an unknown parent shoot" unknown.yaml "unknown.csv:4" "parent 'nobody'" "not a shoot of the table"

printf 'time,shoot,x,y,z\n0,a,0,0.03,0\n1,a,0,0.03,0.01\n' >ok.csv
sed 's/^light:/light:\n  spread: 95/' plant.yaml >spread.yaml
config spread_fit.yaml ok.csv spread.yaml
bad_case "light.spread over 89 degrees" spread_fit.yaml "spread.yaml:26" "light.spread = 95 is outside [0, 89] deg"

sed 's/^tropisms:/tropisms:\n  seek_light: maybe/' plant.yaml >seek.yaml
config seek_fit.yaml ok.csv seek.yaml
bad_case "seek_light neither true nor false" seek_fit.yaml "seek.yaml:31:15" "tropisms.seek_light" "expected a boolean"

config frame.yaml ok.csv
printf '    frame_interval: 0\n' >>frame.yaml
bad_case "frame_interval of 0 s" frame.yaml "frame.yaml:9" "key 'frame_interval'" "expected a time > 0 s, found 0"

config corr.yaml ok.csv
printf '    correlation: 1.5\n' >>corr.yaml
bad_case "correlation above 1" corr.yaml "corr.yaml:9" "key 'correlation'" "expected a number in [0, 1], found 1.5"

config covs.yaml ok.csv
printf '    covariance_seeds: -3\n' >>covs.yaml
bad_case "negative covariance_seeds" covs.yaml "covs.yaml:9" "key 'covariance_seeds'" "0..100000, found -3"

config covat.yaml ok.csv
printf '    covariance_at: fited\n' >>covat.yaml
bad_case "covariance_at neither start nor fitted" covat.yaml "covat.yaml:9:20" "key 'covariance_at'" "expected start or fitted, found 'fited'"

config covr.yaml ok.csv
printf '    covariance_at: fitted\n    covariance_rounds: 0\n' >>covr.yaml
bad_case "covariance_rounds of 0" covr.yaml "covr.yaml:10:24" "key 'covariance_rounds'" "1..100, found 0"

config covt.yaml ok.csv
printf '    covariance_at: fitted\n    covariance_tolerance: -0.1\n' >>covt.yaml
bad_case "negative covariance_tolerance" covt.yaml "covt.yaml:10:27" "key 'covariance_tolerance'" "expected a number > 0, found -0.1"

echo "$PASSED passed, $FAILED failed"
[ "$FAILED" -eq 0 ]
