//! The Metropolis estimators' settings (docs/DESIGN.md §3): the mutation, the bootstrap and
//! the chains, shared by `pssmlt` and `mmlt`.

use super::importance::ImportanceKind;
use crate::error::{Error, Result};
use crate::estimator::Params;
use crate::sampler::primary_sample::Mutation;

/// What the Markov chains do, whatever path function they explore.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChainSettings {
    /// Probability that a proposal is a large step (fresh uniform numbers).
    pub large_step: f64,
    pub mutation: Mutation,
    /// Independent samples that estimate the normalisation b and seed the chains.
    pub bootstrap: u32,
    /// Markov chains; their number and streams do not depend on the thread count.
    pub chains: u32,
    /// Kelemen et al. 2002's weighting of large steps (their MIS of the chain's samples
    /// with the large steps' independent ones), instead of plain expected-value splatting.
    pub kelemen_weights: bool,
    /// What the target density is proportional to (`importance.rs`).
    pub importance: ImportanceKind,
    /// Where the normalisation b comes from.
    pub normalisation: Normalisation,
    /// Whether a chain keeps the stratum it starts in (`mmlt`'s `lengths`; `pssmlt` has
    /// one stratum and leaves it `Mutable`).
    pub lengths: Lengths,
}

/// Whether `mmlt`'s chains may change path length (`--set lengths=…`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lengths {
    /// A state's path length is one of its primary numbers: small steps keep it, large
    /// steps draw it afresh, so a chain wanders over every length.
    Mutable,
    /// Each chain keeps one path length for the whole run, which stratifies the image
    /// over path lengths: the chains are shared out over the lengths in proportion to the
    /// bootstrap's b_d, and a chain of length d weighs its
    /// splats by b_d over its length's share of the mutations. The lengths' shares of the
    /// image are then fixed by the bootstrap instead of by how long the chains linger.
    Fixed,
}

impl Lengths {
    /// Reads `lengths` (fixed, the default, or mutable).
    pub fn from_params(params: &Params) -> Result<Lengths> {
        match params.get("lengths", "fixed".to_string())?.as_str() {
            "mutable" => Ok(Lengths::Mutable),
            "fixed" => Ok(Lengths::Fixed),
            other => Err(Error::usage(format!(
                "--set lengths={other}: expected mutable or fixed"
            ))),
        }
    }
}

/// Where the normalisation b (the mean importance) comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Normalisation {
    /// The bootstrap's estimate, fixed for the whole run (Kelemen et al. 2002): its error
    /// does not shrink with time, and where the importance is heavy-tailed most bootstraps
    /// miss the rare bright points and leave the whole image too dark.
    Bootstrap,
    /// The bootstrap's points and every large step's proposal so far, pooled by their
    /// counts: large steps are independent uniform points too, so b keeps converging while
    /// the chains run (consistent; the splats are scaled by it when the image is read).
    LargeSteps,
}

impl ChainSettings {
    /// Reads `large_step`, `mutation`, `s1`, `s2`, `sigma`, `bootstrap`, `chains`,
    /// `importance`, `normalisation` and, when `with_kelemen_weights`, `kelemen_weights`; each bad value is
    /// an error naming it.
    pub fn from_params(params: &Params, with_kelemen_weights: bool) -> Result<ChainSettings> {
        let large_step: f64 = params.get("large_step", 0.3)?;
        if !(0.0..=1.0).contains(&large_step) {
            return Err(Error::usage(format!(
                "--set large_step={large_step}: must lie in [0, 1]"
            )));
        }
        let s1: f64 = params.get("s1", 1.0 / 1024.0)?;
        let s2: f64 = params.get("s2", 1.0 / 64.0)?;
        let sigma: f64 = params.get("sigma", 0.01)?;
        let mutation = match params.get("mutation", "kelemen".to_string())?.as_str() {
            "kelemen" => {
                if !(s1 > 0.0 && s1.is_finite()) {
                    return Err(Error::usage(format!("--set s1={s1}: must be > 0")));
                }
                if !(s2 > s1 && s2 <= 0.5) {
                    return Err(Error::usage(format!(
                        "--set s2={s2}: must be larger than s1 = {s1} and at most 0.5"
                    )));
                }
                Mutation::Kelemen { s1, s2 }
            }
            "gaussian" => {
                if !(sigma > 0.0 && sigma.is_finite()) {
                    return Err(Error::usage(format!("--set sigma={sigma}: must be > 0")));
                }
                Mutation::Gaussian { sigma }
            }
            other => {
                return Err(Error::usage(format!(
                    "--set mutation={other}: expected kelemen or gaussian"
                )));
            }
        };
        let bootstrap: u32 = params.get("bootstrap", 100_000)?;
        if bootstrap == 0 {
            return Err(Error::usage("--set bootstrap=0: must be at least 1"));
        }
        let chains: u32 = params.get("chains", 256)?;
        if chains == 0 {
            return Err(Error::usage("--set chains=0: must be at least 1"));
        }
        if chains > bootstrap {
            return Err(Error::usage(format!(
                "--set chains={chains}: more chains than bootstrap samples ({bootstrap})"
            )));
        }
        let kelemen_weights = if with_kelemen_weights {
            params.get("kelemen_weights", false)?
        } else {
            false
        };
        let importance = match params.get("importance", "luminance".to_string())?.as_str() {
            "luminance" => ImportanceKind::Luminance,
            "relative" => ImportanceKind::Relative,
            other => {
                return Err(Error::usage(format!(
                    "--set importance={other}: expected luminance or relative"
                )));
            }
        };
        let normalisation = match params
            .get("normalisation", "bootstrap".to_string())?
            .as_str()
        {
            "bootstrap" => Normalisation::Bootstrap,
            "large_steps" if kelemen_weights => {
                return Err(Error::usage(
                    "--set normalisation=large_steps: not with kelemen_weights=true (whose \
                     weights use b while splatting)",
                ));
            }
            "large_steps" => Normalisation::LargeSteps,
            other => {
                return Err(Error::usage(format!(
                    "--set normalisation={other}: expected bootstrap or large_steps"
                )));
            }
        };
        Ok(ChainSettings {
            large_step,
            mutation,
            bootstrap,
            chains,
            kelemen_weights,
            importance,
            normalisation,
            lengths: Lengths::Mutable,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(pairs: &[&str]) -> Result<ChainSettings> {
        ChainSettings::from_params(&Params::parse(pairs).unwrap(), true)
    }

    #[test]
    fn defaults_and_bad_values_name_the_parameter() {
        let d = settings(&[]).unwrap();
        assert_eq!(d.large_step, 0.3);
        assert_eq!(d.chains, 256);
        assert_eq!(d.bootstrap, 100_000);
        assert_eq!(d.importance, ImportanceKind::Luminance);
        assert_eq!(
            d.mutation,
            Mutation::Kelemen {
                s1: 1.0 / 1024.0,
                s2: 1.0 / 64.0
            }
        );
        for (bad, name) in [
            ("large_step=1.5", "large_step"),
            ("large_step=-0.1", "large_step"),
            ("chains=0", "chains"),
            ("bootstrap=0", "bootstrap"),
            ("s2=0.0001", "s2"),
            ("mutation=uniform", "mutation"),
            ("importance=radiance", "importance"),
        ] {
            let e = settings(&[bad]).unwrap_err().to_string();
            assert!(e.contains(name), "{bad}: {e}");
        }
        let e = settings(&["s1=0.1", "s2=0.05"]).unwrap_err().to_string();
        assert!(e.contains("s2"), "{e}");
        let e = settings(&["mutation=gaussian", "sigma=0"])
            .unwrap_err()
            .to_string();
        assert!(e.contains("sigma"), "{e}");
    }
}
