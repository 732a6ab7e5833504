//! Estimator parameters from `--set key=value`: typed look-ups with defaults, and an error
//! for every key no estimator asked for (a misspelt parameter must never be ignored).

use std::cell::RefCell;
use std::collections::{BTreeMap, BTreeSet};
use std::str::FromStr;

use crate::error::{Error, Result};

#[derive(Clone, Debug, Default)]
pub struct Params {
    values: BTreeMap<String, String>,
    queried: RefCell<BTreeSet<String>>,
}

impl Params {
    /// Parses `key=value` strings; a repeated key or a missing `=` is an error.
    pub fn parse<S: AsRef<str>>(pairs: &[S]) -> Result<Params> {
        let mut values = BTreeMap::new();
        for pair in pairs {
            let pair = pair.as_ref();
            let (key, value) = pair
                .split_once('=')
                .ok_or_else(|| Error::usage(format!("--set expects key=value, got '{pair}'")))?;
            let key = key.trim();
            if key.is_empty() {
                return Err(Error::usage(format!("--set '{pair}': empty key")));
            }
            if values
                .insert(key.to_string(), value.trim().to_string())
                .is_some()
            {
                return Err(Error::usage(format!("--set {key} given twice")));
            }
        }
        Ok(Params {
            values,
            queried: RefCell::default(),
        })
    }

    /// The raw value of `key`, if set.
    pub fn raw(&self, key: &str) -> Option<&str> {
        self.queried.borrow_mut().insert(key.to_string());
        self.values.get(key).map(String::as_str)
    }

    /// The value of `key` parsed as `T`, or `default` when absent.
    pub fn get<T: FromStr>(&self, key: &str, default: T) -> Result<T> {
        match self.raw(key) {
            None => Ok(default),
            Some(text) => text.parse().map_err(|_| {
                Error::usage(format!(
                    "--set {key}={text}: expected a {}",
                    std::any::type_name::<T>()
                ))
            }),
        }
    }

    /// Fails when a key was set that nothing asked for, naming the estimator.
    pub fn check_all_used(&self, estimator: &str) -> Result<()> {
        let queried = self.queried.borrow();
        let unknown: Vec<&str> = self
            .values
            .keys()
            .filter(|k| !queried.contains(*k))
            .map(String::as_str)
            .collect();
        if unknown.is_empty() {
            Ok(())
        } else {
            Err(Error::usage(format!(
                "estimator '{estimator}' has no parameter {}",
                unknown.join(", ")
            )))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn typed_values_defaults_and_unknown_keys() {
        let p = Params::parse(&["rr_depth=3", "mis = power"]).unwrap();
        assert_eq!(p.get("rr_depth", 5u32).unwrap(), 3);
        assert_eq!(p.get("alpha", 0.5f32).unwrap(), 0.5);
        assert!(p.check_all_used("pt").is_err()); // `mis` not asked for
        assert_eq!(p.get("mis", String::new()).unwrap(), "power");
        p.check_all_used("pt").unwrap();
        assert!(p.get("mis", 1.0f32).is_err());
        assert!(Params::parse(&["novalue"]).is_err());
        assert!(Params::parse(&["a=1", "a=2"]).is_err());
    }
}
