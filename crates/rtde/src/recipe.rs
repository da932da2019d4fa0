//! Recipes: the agreed field list of a data package, and its encoding.

use super::RtdeError;
use super::types::{RtdeType, RtdeValue};

/// A recipe the controller accepted: names and types in package order.
#[derive(Debug, Clone, PartialEq)]
pub struct Recipe {
    /// Recipe ID (first byte of each data package).
    pub id: u8,
    /// Field names.
    pub names: Vec<String>,
    /// Field types, one per name.
    pub types: Vec<RtdeType>,
}

impl Recipe {
    /// Bytes of one data package's fields (without the recipe ID).
    pub fn data_len(&self) -> usize {
        self.types.iter().map(|t| t.size()).sum()
    }

    /// Position of a field.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// Decodes a data package's field bytes (exactly [`Self::data_len`] bytes).
    pub fn decode(&self, data: &[u8]) -> Result<Vec<RtdeValue>, RtdeError> {
        if data.len() != self.data_len() {
            return Err(RtdeError::DataLength { recipe_id: self.id, expected: self.data_len(), got: data.len() });
        }
        let mut values = Vec::with_capacity(self.types.len());
        let mut at = 0;
        for &t in &self.types {
            let (value, used) = RtdeValue::decode(t, &data[at..])?;
            values.push(value);
            at += used;
        }
        Ok(values)
    }

    /// Encodes values (one per field, matching types) to field bytes.
    pub fn encode(&self, values: &[RtdeValue]) -> Result<Vec<u8>, RtdeError> {
        if values.len() != self.types.len() {
            return Err(RtdeError::ValueCount { recipe_id: self.id, expected: self.types.len(), got: values.len() });
        }
        let mut out = Vec::with_capacity(self.data_len());
        for ((value, &t), name) in values.iter().zip(&self.types).zip(&self.names) {
            if value.rtde_type() != t {
                return Err(RtdeError::TypeMismatch { field: name.clone(), expected: t, got: value.rtde_type() });
            }
            value.encode_into(&mut out);
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hardware_md_input_package_fields() {
        let recipe = Recipe {
            id: 2,
            names: vec!["input_double_register_0".into(), "input_int_register_0".into()],
            types: vec![RtdeType::Double, RtdeType::Int32],
        };
        let data = recipe.encode(&[RtdeValue::Double(1.5), RtdeValue::Int32(7)]).unwrap();
        assert_eq!(data, vec![0x3F, 0xF8, 0, 0, 0, 0, 0, 0, 0, 0, 0, 7]);
        assert_eq!(recipe.decode(&data).unwrap(), vec![RtdeValue::Double(1.5), RtdeValue::Int32(7)]);
        assert!(recipe.decode(&data[..11]).is_err());
        assert!(recipe.encode(&[RtdeValue::Int32(7), RtdeValue::Double(1.5)]).is_err());
        assert!(recipe.encode(&[RtdeValue::Double(1.5)]).is_err());
    }
}
