//! Which SIMD kernels a command runs with: `--isa`, else `$LUMIERE_ISA`, else the widest this CPU
//! has. Forcing one is for tests and benchmarks: every ISA gives the same image bytes.

use lumiere::accel::Isa;
use lumiere::error::quote;
use lumiere::{Error, Result};

/// The environment variable that forces an ISA when `--isa` is absent.
const ENV: &str = "LUMIERE_ISA";

/// An ISA by name, refused unless this CPU can run it.
pub fn parse(name: &str) -> std::result::Result<Isa, String> {
    let isa = Isa::from_name(name.trim())
        .ok_or_else(|| format!("unknown ISA {} (expected {})", quote(name), names(&Isa::ALL)))?;
    if !isa.is_supported() {
        return Err(format!("this CPU cannot run {isa} (it can run {})", names(&Isa::supported())));
    }
    Ok(isa)
}

/// The ISA to build the BVH for.
pub fn choose(flag: Option<Isa>) -> Result<Isa> {
    if let Some(isa) = flag {
        return Ok(isa);
    }
    match std::env::var(ENV) {
        // Set but empty is unset, as for `OIDN_DIR` (`LUMIERE_ISA= lumiere ...` clears it).
        Ok(name) if name.trim().is_empty() => Ok(Isa::detect()),
        Ok(name) => parse(&name).map_err(|why| Error::invalid(format!("{ENV}: {why}"))),
        Err(std::env::VarError::NotPresent) => Ok(Isa::detect()),
        Err(std::env::VarError::NotUnicode(_)) => Err(Error::invalid(format!("{ENV} is not valid UTF-8"))),
    }
}

fn names(isas: &[Isa]) -> String {
    isas.iter().map(|isa| isa.name()).collect::<Vec<_>>().join(", ")
}
