//! Every numeric configuration field against its declared range: NaN, infinities, 0, negative
//! and huge values are refused by `validate` (or by the TOML parser, for whole-number fields)
//! exactly when the range says so, with a message naming the field, the value and the range.

use roar_cli::pipeline::ReconstructConfig;

/// The default configuration with `key` set to `value`, parsed as a user's TOML file would be.
fn with(key: &str, value: toml::Value) -> Result<ReconstructConfig, String> {
    let mut table = toml::Table::try_from(ReconstructConfig::default()).unwrap();
    table.insert(key.to_string(), value);
    toml::from_str::<ReconstructConfig>(&toml::to_string(&table).unwrap())
        .map_err(|e| e.to_string())
}

#[test]
fn every_numeric_field_has_a_range() {
    let config = ReconstructConfig::default();
    config.validate().unwrap();
    let table = toml::Table::try_from(&config).unwrap();
    let ranged: Vec<&str> = config.field_ranges().iter().map(|(r, _)| r.name).collect();
    for (key, value) in &table {
        if value.is_integer() || value.is_float() {
            assert!(
                ranged.contains(&key.as_str()),
                "{key} has no declared range"
            );
        }
    }
    for name in &ranged {
        assert!(table.contains_key(*name), "range for unknown field {name}");
    }
}

#[test]
fn every_numeric_field_refuses_values_outside_its_range() {
    let defaults = ReconstructConfig::default();
    for (range, default) in defaults.field_ranges() {
        let integer = toml::Table::try_from(&defaults).unwrap()[range.name].is_integer();
        let probes = [
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            0.0,
            -1.0,
            1e30,
            range.min,
            range.max,
            default,
            range.max * 2.0 + 1.0,
        ];
        for probe in probes {
            let value =
                if integer && probe.is_finite() && probe.fract() == 0.0 && probe.abs() < 9e18 {
                    toml::Value::Integer(probe as i64)
                } else {
                    toml::Value::Float(probe)
                };
            let expected_ok = range.allows(probe) && (!integer || probe.abs() < 9e18);
            let parsed = with(range.name, value.clone());
            if let Err(message) = &parsed {
                // Whole-number fields: the TOML parser refuses fractions, NaN and infinities.
                assert!(
                    !expected_ok,
                    "{} = {probe} did not parse: {message}",
                    range.name
                );
                assert!(message.contains(range.name), "{}: {message}", range.name);
                continue;
            }
            match (parsed.unwrap().validate(), expected_ok) {
                (Ok(()), true) => {}
                (Err(message), true) => {
                    // Allowed by its own range, but in conflict with another field's rule.
                    assert!(
                        message.contains("working_budget_min") && message.contains("above"),
                        "{} = {probe}: {message}",
                        range.name
                    );
                }
                (Ok(()), false) => panic!("{} = {probe} was accepted", range.name),
                (Err(message), false) => {
                    assert!(message.contains(range.name), "{}: {message}", range.name);
                    assert!(message.contains(&probe.to_string()), "{message}");
                    assert_eq!(message.lines().count(), 1, "{message}");
                }
            }
        }
    }
}

#[test]
fn range_errors_name_field_value_and_range() {
    let config = with("render_weight", toml::Value::Float(f64::NAN)).unwrap();
    assert_eq!(
        config.validate().unwrap_err(),
        "render_weight = NaN is out of range: allowed 0 to 1000000"
    );
    let config = with("sliver_quality", toml::Value::Float(0.5)).unwrap();
    assert!(config.validate().unwrap_err().contains("0 (off) or 1 to"));
}

#[test]
fn working_budget_bounds_must_be_ordered() {
    let config = with("working_budget_min", toml::Value::Integer(30_000)).unwrap();
    let message = config.validate().unwrap_err();
    assert!(message.contains("working_budget_min = 30000 is above working_budget_max = 20000"));
}
