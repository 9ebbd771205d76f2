//! Bad input through every command: the commands are enumerated from `wscg --help`, so a new
//! command is covered when it is added. Each must fail with exit status 2 and an `error:` line
//! that names the file or the option, never a panic or a signal.

mod common;

use common::wscg;

/// The help text of `wscg PATH... --help`.
fn help(path: &[String]) -> String {
    let out = wscg().args(path).arg("--help").output().unwrap();
    assert!(out.status.success(), "wscg {path:?} --help failed");
    String::from_utf8(out.stdout).unwrap()
}

/// The subcommands listed under `Commands:` (without `help`).
fn subcommands(text: &str) -> Vec<String> {
    let Some(rest) = text.split("Commands:\n").nth(1) else {
        return Vec::new();
    };
    rest.lines()
        .take_while(|l| !l.trim().is_empty())
        .filter(|l| l.starts_with("  ") && !l.starts_with("    "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .map(str::to_string)
        .collect()
}

/// Every leaf command with its help text, demos and the gallery excepted (built-in data).
fn leaves(path: Vec<String>, out: &mut Vec<(Vec<String>, String)>) {
    let text = help(&path);
    let subs = subcommands(&text);
    if subs.is_empty() {
        out.push((path, text));
        return;
    }
    for s in subs {
        if path.is_empty() && (s == "demo" || s == "gallery") {
            continue;
        }
        let mut p = path.clone();
        p.push(s);
        leaves(p, out);
    }
}

/// One option of a help text: its flag, whether it takes a value, and its default.
struct Opt {
    flag: String,
    default: Option<String>,
}

fn options(text: &str) -> Vec<Opt> {
    let Some(section) = text.split("Options:\n").nth(1) else {
        return Vec::new();
    };
    let mut opts: Vec<(String, bool, String)> = Vec::new();
    for line in section.lines() {
        let t = line.trim_start();
        let indent = line.len() - t.len();
        if t.starts_with('-') && indent <= 6 {
            let flag = t
                .split_whitespace()
                .find(|w| w.starts_with("--"))
                .map(|w| w.trim_end_matches(',').to_string());
            if let Some(flag) = flag {
                let takes = t.contains(" <");
                opts.push((flag, takes, t.to_string()));
            }
        } else if let Some(last) = opts.last_mut() {
            last.2.push(' ');
            last.2.push_str(t);
        }
    }
    opts.into_iter()
        .filter(|(_, takes, _)| *takes)
        .map(|(flag, _, text)| Opt {
            flag,
            default: text
                .split("[default: ")
                .nth(1)
                .and_then(|d| d.split(']').next())
                .map(str::to_string),
        })
        .collect()
}

fn all_commands() -> Vec<(Vec<String>, String)> {
    let mut out = Vec::new();
    leaves(Vec::new(), &mut out);
    assert!(out.len() > 40, "only {} commands found", out.len());
    out
}

/// Asserts a clean failure whose message contains one of `names`.
fn assert_clean_failure(args: &[String], out: &std::process::Output, names: &[String]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "wscg {args:?}: {err}");
    assert!(!err.contains("panicked"), "wscg {args:?} panicked: {err}");
    assert!(
        err.trim_start().starts_with("error:"),
        "wscg {args:?}: no error line: {err}"
    );
    assert!(
        names.iter().any(|n| err.contains(n.as_str())),
        "wscg {args:?}: the error names none of {names:?}: {err}"
    );
}

#[test]
fn non_finite_numbers_are_refused_naming_the_option() {
    let mut checked = 0;
    for (path, text) in all_commands() {
        for opt in options(&text) {
            let numeric = opt
                .default
                .as_deref()
                .is_some_and(|d| d.parse::<f64>().is_ok());
            if !numeric {
                continue;
            }
            for bad in ["nan", "inf"] {
                let mut args = path.clone();
                args.extend([opt.flag.clone(), bad.to_string()]);
                let out = wscg().args(&args).output().unwrap();
                assert_clean_failure(&args, &out, std::slice::from_ref(&opt.flag));
                checked += 1;
            }
        }
    }
    assert!(checked > 150, "only {checked} numeric options found");
}

/// Positional arguments that name an output (a file or a folder to create).
const OUTPUT_POSITIONALS: [&str; 2] = ["OUTPUT", "DIR"];

#[test]
fn missing_input_files_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let mut checked = 0;
    for (path, text) in all_commands() {
        let usage = text
            .lines()
            .find_map(|l| l.strip_prefix("Usage: "))
            .unwrap()
            .to_string();
        let required = usage.split("[OPTIONS]").last().unwrap_or("");
        let words: Vec<&str> = required.split_whitespace().collect();
        let mut args = path.clone();
        let mut names = Vec::new();
        let mut inputs = 0;
        let mut i = 0;
        while i < words.len() {
            let w = words[i];
            if w.starts_with("--") && i + 1 < words.len() {
                let flag = w.to_string();
                let value = if flag == "--out" || flag == "--out-dir" {
                    dir.path()
                        .join(format!("out-{}", path.join("-")))
                        .display()
                        .to_string()
                } else {
                    inputs += 1;
                    let f = dir
                        .path()
                        .join(format!("missing{}.dat", flag.replace('-', "")));
                    names.push(f.file_name().unwrap().to_string_lossy().to_string());
                    f.display().to_string()
                };
                names.push(flag.clone());
                args.extend([flag, value]);
                i += 2;
            } else if w.starts_with('<') {
                // Required positionals (`<NAME>`); `[NAME]...` are optional.
                let name = w.trim_matches(|c| c == '<' || c == '>' || c == '.');
                if OUTPUT_POSITIONALS.contains(&name) {
                    args.push(dir.path().join(format!("out-{name}")).display().to_string());
                    i += 1;
                    continue;
                }
                inputs += 1;
                let f = dir
                    .path()
                    .join(format!("missing-{}.dat", name.to_lowercase()));
                names.push(f.file_name().unwrap().to_string_lossy().to_string());
                names.push(name.to_string());
                args.push(f.display().to_string());
                i += 1;
            } else {
                i += 1;
            }
        }
        if inputs == 0 {
            continue; // generators: nothing to read
        }
        let out = wscg().args(&args).output().unwrap();
        assert_clean_failure(&args, &out, &names);
        checked += 1;
    }
    assert!(checked > 25, "only {checked} commands with inputs found");
}
