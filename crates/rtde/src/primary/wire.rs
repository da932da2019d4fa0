//! Big-endian writing and reading of the primary interface's fields (network byte order, as UR's
//! client interface document states for every field).

use super::error::PrimaryError;

/// Appends fields to a package body.
#[derive(Debug, Default)]
pub(crate) struct Writer(pub(crate) Vec<u8>);

impl Writer {
    pub(crate) fn u8(&mut self, v: u8) -> &mut Self {
        self.0.push(v);
        self
    }
    pub(crate) fn i8(&mut self, v: i8) -> &mut Self {
        self.0.extend_from_slice(&v.to_be_bytes());
        self
    }
    pub(crate) fn bool(&mut self, v: bool) -> &mut Self {
        self.u8(u8::from(v))
    }
    pub(crate) fn u32(&mut self, v: u32) -> &mut Self {
        self.0.extend_from_slice(&v.to_be_bytes());
        self
    }
    pub(crate) fn i32(&mut self, v: i32) -> &mut Self {
        self.0.extend_from_slice(&v.to_be_bytes());
        self
    }
    pub(crate) fn u64(&mut self, v: u64) -> &mut Self {
        self.0.extend_from_slice(&v.to_be_bytes());
        self
    }
    pub(crate) fn f32(&mut self, v: f32) -> &mut Self {
        self.0.extend_from_slice(&v.to_be_bytes());
        self
    }
    pub(crate) fn f64(&mut self, v: f64) -> &mut Self {
        self.0.extend_from_slice(&v.to_be_bytes());
        self
    }
    pub(crate) fn f64s(&mut self, v: &[f64]) -> &mut Self {
        for x in v {
            self.f64(*x);
        }
        self
    }
    pub(crate) fn bytes(&mut self, v: &[u8]) -> &mut Self {
        self.0.extend_from_slice(v);
        self
    }
}

/// Takes fields off the front of a package body; every read checks the length.
#[derive(Debug)]
pub(crate) struct Reader<'a>(pub(crate) &'a [u8]);

impl<'a> Reader<'a> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], PrimaryError> {
        if self.0.len() < N {
            return Err(PrimaryError::Truncated { needed: N, available: self.0.len() });
        }
        let (head, rest) = self.0.split_at(N);
        self.0 = rest;
        Ok(head.try_into().expect("split at N"))
    }
    pub(crate) fn u8(&mut self) -> Result<u8, PrimaryError> {
        Ok(self.take::<1>()?[0])
    }
    pub(crate) fn i8(&mut self) -> Result<i8, PrimaryError> {
        Ok(i8::from_be_bytes(self.take()?))
    }
    pub(crate) fn bool(&mut self) -> Result<bool, PrimaryError> {
        Ok(self.u8()? != 0)
    }
    pub(crate) fn u32(&mut self) -> Result<u32, PrimaryError> {
        Ok(u32::from_be_bytes(self.take()?))
    }
    pub(crate) fn i32(&mut self) -> Result<i32, PrimaryError> {
        Ok(i32::from_be_bytes(self.take()?))
    }
    pub(crate) fn u64(&mut self) -> Result<u64, PrimaryError> {
        Ok(u64::from_be_bytes(self.take()?))
    }
    pub(crate) fn f32(&mut self) -> Result<f32, PrimaryError> {
        Ok(f32::from_be_bytes(self.take()?))
    }
    pub(crate) fn f64(&mut self) -> Result<f64, PrimaryError> {
        Ok(f64::from_be_bytes(self.take()?))
    }
    pub(crate) fn f64s<const N: usize>(&mut self) -> Result<[f64; N], PrimaryError> {
        let mut out = [0.0; N];
        for x in &mut out {
            *x = self.f64()?;
        }
        Ok(out)
    }
    pub(crate) fn bytes(&mut self, n: usize) -> Result<&'a [u8], PrimaryError> {
        if self.0.len() < n {
            return Err(PrimaryError::Truncated { needed: n, available: self.0.len() });
        }
        let (head, rest) = self.0.split_at(n);
        self.0 = rest;
        Ok(head)
    }
    /// The rest of the body as text (UR's variable-length strings that run to the end).
    pub(crate) fn rest_text(&mut self) -> String {
        let text = String::from_utf8_lossy(self.0).into_owned();
        self.0 = &[];
        text
    }
}
