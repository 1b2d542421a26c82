//! What every output says about the law a run used: its name, whether it
//! is model-based, and the parameters it takes with their values.

use controller::{ControllerParams, LawName};
use serde::Serialize;

/// The law of a run, as reports, logs and `compare` describe it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LawInfo {
    /// The law's name (`nac`, `pd`, …).
    pub law: LawName,
    /// True for `pd-gravity` and `ctc`: they use the URDF's M, C, G, which a
    /// model-free law does not have.
    pub model_based: bool,
    /// The keys the law takes, with the run's values.
    pub parameters: serde_json::Map<String, serde_json::Value>,
}

impl LawInfo {
    /// The law of `params`.
    pub fn of(params: &ControllerParams) -> Self {
        let law = params.law;
        let parameters = match serde_json::to_value(params) {
            Ok(serde_json::Value::Object(all)) => all
                .into_iter()
                .filter(|(k, _)| law.takes(k) && k != "law")
                .collect(),
            // A struct of numbers and enums always serialises to an object.
            _ => serde_json::Map::new(),
        };
        Self {
            law,
            model_based: law.model_based(),
            parameters,
        }
    }

    /// One line for tables: "law ctc (model-based: M, C, G from the URDF)".
    pub fn label(&self) -> String {
        if self.model_based {
            format!("{} (model-based: M, C, G from the URDF)", self.law)
        } else {
            format!("{} (model-free)", self.law)
        }
    }

    /// The parameters as `key=value` pairs, for the log's metadata.
    pub fn parameters_text(&self) -> String {
        self.parameters
            .iter()
            .map(|(k, v)| format!("{k}={v}"))
            .collect::<Vec<_>>()
            .join(",")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameters_are_the_laws_own() {
        let ctc = LawInfo::of(&ControllerParams {
            law: LawName::Ctc,
            model_scale: 0.8,
            ..Default::default()
        });
        assert!(ctc.model_based && ctc.label().contains("model-based"));
        let keys: Vec<&str> = ctc.parameters.keys().map(String::as_str).collect();
        assert_eq!(keys, ["k1", "k2", "model_scale", "tc"]);
        assert!(ctc.parameters_text().contains("model_scale=0.8"));
        let nac = LawInfo::of(&ControllerParams::default());
        assert!(nac.parameters.contains_key("beta") && !nac.model_based);
    }
}
