//! The `collide` binary as a user meets it: outputs, exit codes, and error messages.

use std::io::Write;
use std::process::{Command, Output, Stdio};

fn collide(args: &[&str], stdin: &str) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_collide"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    child.stdin.take().unwrap().write_all(stdin.as_bytes()).unwrap();
    child.wait_with_output().unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8(bytes.to_vec()).unwrap()
}

#[test]
fn roots_prints_exact_roots_in_decimal_or_hex() {
    let out = collide(&["roots", "1", "-1e8", "1"], "");
    assert!(out.status.success());
    assert_eq!(text(&out.stdout), "1e-8 99999999.99999999\n");
    let out = collide(&["roots", "--hex", "0x1p0", "-0x1.8p+1", "2"], "");
    assert_eq!(text(&out.stdout), "0x1p+0 0x1p+1\n");
    assert_eq!(text(&collide(&["roots", "1", "0", "1"], "").stdout), "none\n");
    assert_eq!(text(&collide(&["roots", "0", "-0", "0"], "").stdout), "all\n");
}

#[test]
fn roots_rejects_bad_numbers_with_a_clear_message() {
    let out = collide(&["roots", "1", "nan", "2"], "");
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    assert!(err.contains("coefficient B") && err.contains("'nan' is not a finite f64"), "{err}");
    assert!(!err.contains("panicked") && !err.contains("backtrace"), "{err}");
    let out = collide(&["roots", "1", "2"], "");
    assert_eq!(out.status.code(), Some(2), "two coefficients is a usage error");
}

#[test]
fn contact_time_prints_time_or_never() {
    let args =
        ["contact-time", "--r1", "0,0", "--v1", "1,0", "--R1", "0.5", "--r2", "3,0", "--v2", "-1,0", "--R2", "0.5"];
    let out = collide(&args, "");
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(text(&out.stdout), "1.0\n");
    let never =
        ["contact-time", "--r1", "0,0", "--v1", "0,0", "--R1", "0.5", "--r2", "3,0", "--v2", "1,0", "--R2", "0.5"];
    assert_eq!(text(&collide(&never, "").stdout), "never\n");
    let spheres =
        ["contact-time", "--r1=0,0,0", "--v1=0,0,0", "--R1=1", "--r2=0,0,4", "--v2=0,0,-1", "--R2=1", "--hex"];
    assert_eq!(text(&collide(&spheres, "").stdout), "0x1p+1\n");
    let bad =
        ["contact-time", "--r1", "0,0", "--v1", "1,0", "--R1", "-0.5", "--r2", "3,0", "--v2", "-1,0", "--R2", "0.5"];
    let out = collide(&bad, "");
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("R1 = -0.5 is negative"), "{}", text(&out.stderr));
    let missing = collide(&["contact-time", "--r1", "0,0"], "");
    assert_eq!(missing.status.code(), Some(2));
    assert!(text(&missing.stderr).contains("missing --v1"), "{}", text(&missing.stderr));
}

/// Growing radii: `--g1`/`--g2` on the one-shot form, `"g1"`/`"g2"` in JSON lines; every
/// growing case of the edge-case reference answered by the CLI exactly as stored (hex out).
#[test]
fn contact_time_takes_growth_rates() {
    let grow =
        ["contact-time", "--r1", "0,0", "--v1", "0,0", "--R1", "0.5", "--r2", "3,0", "--v2", "0,0", "--R2", "0.5"];
    assert_eq!(text(&collide(&grow, "").stdout), "never\n");
    let with = [&grow[..], &["--g1", "0.5", "--g2", "0x1p-1"]].concat();
    assert_eq!(text(&collide(&with, "").stdout), "2.0\n");
    let bad = [&grow[..], &["--g1=-0.5"]].concat();
    let out = collide(&bad, "");
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("g1 = -0.5 is negative; a growth rate must be ≥ 0"), "{}", text(&out.stderr));
    let out = collide(&[&grow[..], &["--g2", "fast"]].concat(), "");
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("--g2"), "{}", text(&out.stderr));

    use quadratic::reference::{GROWING_CASES, describe_contact};
    let hex = quadratic::hex::format;
    let vector = |v: [f64; 2]| format!("[\"{}\", \"{}\"]", hex(v[0]), hex(v[1]));
    let mut input = String::new();
    for (k, c) in GROWING_CASES.iter().enumerate() {
        input += &format!(
            "{{\"id\": {k}, \"r1\": {}, \"v1\": {}, \"R1\": \"{}\", \"r2\": {}, \"v2\": {}, \"R2\": \"{}\", \"g1\": \"{}\", \"g2\": \"{}\"}}\n",
            vector(c.first.position),
            vector(c.first.velocity),
            hex(c.first.radius),
            vector(c.second.position),
            vector(c.second.velocity),
            hex(c.second.radius),
            hex(c.rates[0]),
            hex(c.rates[1]),
        );
    }
    let out = collide(&["contact-time", "--jsonl", "--hex"], &input);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let lines: Vec<String> = text(&out.stdout).lines().map(String::from).collect();
    assert_eq!(lines.len(), GROWING_CASES.len());
    for (line, c) in lines.iter().zip(GROWING_CASES) {
        let want = match c.exact.time() {
            None => "null".to_string(),
            Some(t) => format!("\"{}\"", hex(t)),
        };
        assert!(line.ends_with(&format!("\"t\":{want}}}")), "{}: {line} for {}", c.name, describe_contact(&c.exact));
    }
}

#[test]
fn jsonl_answers_every_good_line_and_fails_at_the_end_for_bad_ones() {
    let input = "{\"id\": \"a\", \"a\": 1, \"b\": -3, \"c\": 2}\n{\"id\": 2, \"a\": 1\n{\"id\": 3, \"a\": \"0x1p-1074\", \"b\": 0, \"c\": \"-0x1p-1074\"}\n";
    let out = collide(&["roots", "--jsonl"], input);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(text(&out.stdout), "{\"id\":\"a\",\"roots\":[1.0,2.0]}\n{\"id\":3,\"roots\":[-1.0,1.0]}\n");
    let err = text(&out.stderr);
    assert!(err.starts_with("line 2: not valid JSON"), "{err}");
    assert!(err.contains("1 line(s) could not be answered"), "{err}");

    let input =
        "{\"id\": 7, \"r1\": [0, 0], \"v1\": [1, 0], \"R1\": 0.5, \"r2\": [3, 0], \"v2\": [-1, 0], \"R2\": 0.5}\n";
    let out = collide(&["contact-time", "--jsonl", "--hex"], input);
    assert!(out.status.success());
    assert_eq!(text(&out.stdout), "{\"id\":7,\"t\":\"0x1p+0\"}\n");
}

#[test]
fn check_verifies_the_reference_cases() {
    let out = collide(&["check"], "");
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    assert!(stdout.contains("agree with the exact answers"), "{stdout}");
    assert!(!stdout.contains("MISMATCH"));
}

/// A point timed in two threads says so and times about the collisions asked for; pinned to
/// one core it is refused. (That its events are one thread's, bit for bit, is the library's
/// test `bench::tests::two_threads_run_the_whole_box_events`.)
#[test]
fn bench_point_runs_in_two_threads() {
    let args =
        ["bench-point", "--dimension", "3", "--n", "2048", "--eta", "0.45", "--warmup", "20", "--timed", "20000"];
    let out = collide(&[&args[..], &["--threads", "2"]].concat(), "");
    assert!(out.status.success(), "{}", text(&out.stderr));
    let point: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(point["threads"].as_u64(), Some(2));
    let collisions = point["collisions"].as_u64().unwrap();
    // The end time comes from the rate of the warm-up's second half: about the collisions
    // asked for (19 881 with this seed).
    assert!((19_000..21_000).contains(&collisions), "{collisions} collisions for 20 000 asked");
    assert_eq!(point["events_by_kind"]["pair"].as_u64(), Some(collisions));
    let out = collide(&args, "");
    let point: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!((point["threads"].as_u64(), point["collisions"].as_u64()), (Some(1), Some(20_000)));
    // Pinned to one core, two threads are refused with the reason, before anything runs
    // (where `taskset` exists and may pin to core 0; its own refusal starts "taskset:").
    if let Ok(out) = std::process::Command::new("taskset")
        .args(["-c", "0", env!("CARGO_BIN_EXE_collide")])
        .args(args)
        .args(["--threads", "2"])
        .output()
        && !text(&out.stderr).starts_with("taskset:")
    {
        assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
        assert!(
            text(&out.stderr).contains("--threads 2: 1 only: this process may run on one core"),
            "{}",
            text(&out.stderr)
        );
        assert!(out.stdout.is_empty());
    }
}

/// The benchmark's neighbourhood can be forced; a name that is not one is refused with the
/// names allowed, before anything runs or is written.
#[test]
fn bench_takes_a_neighbourhood_and_refuses_unknown_ones() {
    let out = collide(
        &["bench-point", "--n", "500", "--eta", "0.65", "--warmup", "1", "--timed", "2000", "--neighbourhood", "grid"],
        "",
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let point: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!((point["neighbourhood"].as_str(), point["lists"].as_bool()), (Some("grid"), Some(false)));
    let out = collide(&["bench-point", "--n", "500", "--eta", "0.65", "--warmup", "1", "--timed", "2000"], "");
    let point: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!((point["neighbourhood"].as_str(), point["lists"].as_bool()), (Some("auto"), Some(true)));
    let dir = std::env::temp_dir().join(format!("collide-bench-refused-{}", std::process::id()));
    let out = collide(&["bench", "--quick", "--neighbourhood", "list", "--out", dir.to_str().unwrap()], "");
    assert!(!out.status.success());
    let err = text(&out.stderr);
    assert!(err.contains("\"list\"") && err.contains("auto, grid, lists"), "{err}");
    assert!(!dir.exists(), "nothing is written for a refused command");
}
