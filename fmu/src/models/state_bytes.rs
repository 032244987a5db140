//! The framing of a serialized FMU state, model-neutral: the state magics,
//! the format version, the header size, and the little-endian writer and
//! bounds-checked reader the models write and read their parts with. The
//! snapshots and their header live in [`crate::instance::snapshot`].

/// First bytes of a serialized FMU state of a yarn bundle.
pub const YARN_STATE_MAGIC: &[u8; 8] = b"YBFMUST\0";

/// First bytes of a serialized FMU state of a mass-spring system.
pub const MASS_SPRING_STATE_MAGIC: &[u8; 8] = b"MSFMUST\0";

/// Every state magic this library writes.
pub const STATE_MAGICS: [&[u8; 8]; 2] = [YARN_STATE_MAGIC, MASS_SPRING_STATE_MAGIC];

/// Format version of the serialized FMU state.
/// Version 2: the YarnBundle part holds the transfer scheme, the
/// `transfer.flip_ratio` override, the pin inputs and the pin force sums.
/// Version 3: the YarnBundle part no longer repeats gravity and the
/// attractor, which only the library's state bytes hold.
/// Version 4: the YarnBundle part holds the `integrator` override.
pub const STATE_VERSION: u32 = 4;

pub(crate) const STATE_HEADER: usize = 8 + 4 + 8 + 8;

/// Little-endian writer of a serialized FMU state.
pub struct Writer(Vec<u8>);

impl Writer {
    /// A writer whose first `header` bytes are zero, to be filled in last.
    pub(crate) fn with_header(header: usize) -> Self {
        Writer(vec![0; header])
    }
    /// The bytes written.
    pub(crate) fn into_bytes(self) -> Vec<u8> {
        self.0
    }
    pub fn u8(&mut self, v: u8) {
        self.0.push(v);
    }
    pub fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub fn opt_f64(&mut self, v: Option<f64>) {
        self.u8(v.is_some() as u8);
        self.f64(v.unwrap_or(0.0));
    }
    pub fn bytes(&mut self, b: &[u8]) {
        self.u64(b.len() as u64);
        self.0.extend_from_slice(b);
    }
    /// Like [`Self::bytes`] for the `len` bytes `write` appends (no copy).
    pub fn bytes_with<E>(
        &mut self,
        len: usize,
        write: impl FnOnce(&mut Vec<u8>) -> Result<(), E>,
    ) -> Result<(), E> {
        self.u64(len as u64);
        let start = self.0.len();
        write(&mut self.0)?;
        assert_eq!(self.0.len() - start, len, "declared length of a byte field");
        Ok(())
    }
}

/// Reader of a serialized FMU state; every read is bounds-checked and
/// non-finite numbers are refused.
pub struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    /// A reader at the start of `b`.
    pub(crate) fn new(b: &'a [u8]) -> Self {
        Reader { b, at: 0 }
    }
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        if self.b.len() - self.at < n {
            return Err(format!(
                "state is truncated: {} more bytes needed at offset {}",
                n, self.at
            ));
        }
        let s = &self.b[self.at..self.at + n];
        self.at += n;
        Ok(s)
    }
    pub fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }
    pub fn bool(&mut self) -> Result<bool, String> {
        match self.u8()? {
            0 => Ok(false),
            1 => Ok(true),
            b => Err(format!("bad flag byte {b}")),
        }
    }
    pub fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().unwrap()))
    }
    pub fn f64(&mut self) -> Result<f64, String> {
        let v = f64::from_le_bytes(self.take(8)?.try_into().unwrap());
        if v.is_finite() {
            Ok(v)
        } else {
            Err("state contains a non-finite number".into())
        }
    }
    pub fn opt_f64(&mut self) -> Result<Option<f64>, String> {
        let some = self.bool()?;
        let v = self.f64()?;
        Ok(some.then_some(v))
    }
    pub fn bytes(&mut self) -> Result<&'a [u8], String> {
        let n = self.u64()?;
        let n = usize::try_from(n).map_err(|_| "bad length".to_string())?;
        self.take(n)
    }
    pub fn string(&mut self) -> Result<String, String> {
        String::from_utf8(self.bytes()?.to_vec()).map_err(|_| "string is not UTF-8".to_string())
    }
    /// Fails unless every byte was read.
    pub fn finish(&self) -> Result<(), String> {
        if self.at == self.b.len() {
            Ok(())
        } else {
            Err(format!(
                "state has {} unexpected trailing bytes",
                self.b.len() - self.at
            ))
        }
    }
}
