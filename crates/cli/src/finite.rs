//! Every floating-point option of the command line takes finite numbers only: `nan`, `inf`
//! and `-inf`, which Rust's float parser accepts, are refused while parsing, with clap's
//! error naming the option.

use std::any::TypeId;

use clap::Command;

/// `cmd` with every `f64` / `f32` option and argument (in all subcommands) parsed by a
/// finite-only parser of the same type, so the derived structs are unchanged.
pub fn finite_floats(cmd: Command) -> Command {
    cmd.mut_args(|arg| {
        let id = arg.get_value_parser().type_id();
        if id == TypeId::of::<f64>() {
            arg.value_parser(finite::<f64>)
        } else if id == TypeId::of::<f32>() {
            arg.value_parser(finite::<f32>)
        } else {
            arg
        }
    })
    .mut_subcommands(finite_floats)
}

/// A finite number of type `T`.
fn finite<T: std::str::FromStr + Into<f64> + Copy>(s: &str) -> Result<T, String>
where
    T::Err: std::fmt::Display,
{
    let v: T = s.trim().parse().map_err(|e: T::Err| e.to_string())?;
    if v.into().is_finite() {
        Ok(v)
    } else {
        Err(format!("must be a finite number, got {s}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::{CommandFactory, FromArgMatches, Parser};

    #[derive(Parser, Debug)]
    struct Args {
        #[arg(long, default_value_t = 1.0)]
        sigma: f64,
        #[arg(long)]
        gain: Option<f32>,
        #[arg(long, num_args = 1..)]
        times: Vec<f64>,
        #[arg(long, default_value_t = 3)]
        count: u32,
    }

    fn parse(argv: &[&str]) -> Result<Args, clap::Error> {
        let m = finite_floats(Args::command()).try_get_matches_from(argv)?;
        Args::from_arg_matches(&m)
    }

    #[test]
    fn non_finite_values_are_refused_naming_the_option() {
        for (flag, v) in [("--sigma", "nan"), ("--gain", "inf"), ("--times", "-inf")] {
            let e = parse(&["x", &format!("{flag}={v}")])
                .unwrap_err()
                .to_string();
            assert!(e.contains(flag) && e.contains("finite"), "{e}");
        }
        let a = parse(&["x", "--sigma", "2.5", "--gain=-1", "--times", "1", "2"]).unwrap();
        assert_eq!(
            (a.sigma, a.gain, a.times, a.count),
            (2.5, Some(-1.0), vec![1.0, 2.0], 3)
        );
        assert!(parse(&["x", "--sigma", "abc"]).is_err());
    }
}
