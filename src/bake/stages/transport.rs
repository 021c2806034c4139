//! The `transport` stage: k-bounce and infinite-bounce transport, whole or in shards (an
//! infinite-bounce transport's panels of columns, solved from factors its merge prepared once).

use super::{record, StageRun};
use crate::bake::estimate::{PlanState, PlannedStage};
use crate::bake::workspace::Workspace;
use crate::baked::shard::{Mapped, Payload};
use crate::baked::{self, BakeTransaction, StageRecord};
use crate::error::{Error, Result};
use crate::pipeline::knobs::TransportKnobs;
use crate::progress::Progress;
use crate::radiosity::transport::infinite::{InfiniteFactor, InfiniteSolver};
use crate::radiosity::transport::lu_panels::{panel_count, Factored, Panel};
use crate::radiosity::transport::shard::{
    channels as transport_channels, factor_channels, part_memory, part_panels, solve_part,
    Assembly, ChannelFactors, ChannelPart,
};
use crate::radiosity::transport::{
    memory_estimate, transport, Bounces, Transport, TransportParams,
};
use std::path::PathBuf;

/// The GEMM's per-thread packing buffers (`private-gemm-x86`, thread-local, reserved at 64 MiB
/// each but touched only as far as the products need): what the transport touches stays
/// resident for the later stages. Measured on the Cornell box (592 patches, 2 threads): the
/// reorder and encode stages' peak RSS exceeded their plans by 4.2 and 3.8 MiB, with every
/// other term of the plan accounted for (heaptrack).
const GEMM_SCRATCH: u64 = 4 << 20;

impl StageRun for TransportKnobs {
    fn run(
        &self,
        ws: &mut Workspace,
        txn: &mut BakeTransaction,
        progress: &dyn Progress,
    ) -> Result<StageRecord> {
        let albedo = albedos(ws.patches()?);
        let n = albedo.len();
        let budget = ws.memory_budget();
        let f = ws.form_factors()?;
        check_shape(f.n, n)?;
        let t = transport(
            &f.values,
            n,
            &albedo,
            &TransportParams {
                bounces: self.bounces,
                power: self.power,
                max_memory: budget,
                solver: Default::default(),
            },
            progress,
        )?;
        self.finish(ws, txn, n, t)
    }

    fn shardable(&self) -> bool {
        self.bounces == Bounces::Infinite
    }

    fn prepare_shards(&self, ws: &mut Workspace) -> Result<Option<Payload>> {
        let budget = ws.memory_budget();
        let albedo = albedos(ws.patches()?);
        let f = ws.form_factors_mapped()?;
        check_shape(f.n(), albedo.len())?;
        let factors = factor_channels(f.values(), &albedo, Default::default(), budget)?;
        let mut p = Payload::default();
        for (c, fc) in factors.into_iter().enumerate() {
            p.f64s.insert(format!("error_{c}"), vec![fc.error]);
            p.u32s.insert(format!("solver_{c}"), vec![fc.solver as u32]);
            let perm = match fc.factor {
                InfiniteFactor::F32(lu) => {
                    let (v, perm) = lu.to_parts();
                    p.f32s.insert(format!("lu_{c}"), v);
                    perm
                }
                InfiniteFactor::F64(lu) => {
                    let (v, perm) = lu.to_parts();
                    p.f64s.insert(format!("lu_{c}"), v);
                    perm
                }
            };
            p.u64s.insert(format!("perm_{c}"), perm);
        }
        Ok(Some(p))
    }

    fn run_shard(
        &self,
        ws: &mut Workspace,
        index: usize,
        count: usize,
        prepared: Option<Mapped>,
        _progress: &dyn Progress,
    ) -> Result<(String, Payload)> {
        let albedo = albedos(ws.patches()?);
        let n = albedo.len();
        let prepared = prepared.ok_or_else(|| {
            Error::verify(
                "transport-prepared.0-of-1.shard",
                "the transport's shards need the factors that `relume-bake merge` writes into the shard directory after merging the form factors: run that merge first",
            )
        })?;
        let f = ws.form_factors_mapped()?;
        check_shape(f.n(), n)?;
        let channels = transport_channels(&albedo);
        let mut p = Payload::default();
        for c in 0..channels {
            // One channel's factors at a time.
            let factors = read_factors(&prepared, c, n)?;
            let part = solve_part(f.values(), &albedo, c, &factors, index, count)?;
            let (cols, vals): (Vec<Vec<u32>>, Vec<Vec<f32>>) = part
                .panels
                .into_iter()
                .map(|p| (p.columns, p.values))
                .unzip();
            p.u64s.insert(
                format!("panel_widths_{c}"),
                cols.iter().map(|c| c.len() as u64).collect(),
            );
            p.u32s.insert(format!("columns_{c}"), cols.concat());
            p.f32s.insert(format!("values_{c}"), vals.concat());
        }
        let r = part_panels(n, index, count);
        Ok((
            format!(
                "panels {}..{} of {}, n = {n}",
                r.start,
                r.end,
                panel_count(n)
            ),
            p,
        ))
    }

    fn merge_shards(
        &self,
        ws: &mut Workspace,
        txn: &mut BakeTransaction,
        shards: Vec<PathBuf>,
        prepared: Option<Mapped>,
    ) -> Result<StageRecord> {
        let albedo = albedos(ws.patches()?);
        let n = albedo.len();
        let prepared = prepared.ok_or_else(|| {
            Error::verify(
                "transport-prepared.0-of-1.shard",
                "missing beside the transport's shards (the merge of the previous round writes it)",
            )
        })?;
        let channels = transport_channels(&albedo);
        let solvers = (0..channels)
            .map(|c| read_solver(&prepared, c))
            .collect::<Result<Vec<_>>>()?;
        drop(prepared);
        let count = shards.len();
        let mut assembly = Assembly::new(&albedo, &solvers, count)?;
        for (i, path) in shards.into_iter().enumerate() {
            let (_, mut p) = crate::baked::shard::read(&path)?;
            let mut part = Vec::with_capacity(channels);
            for c in 0..channels {
                let widths = p.u64s(&format!("panel_widths_{c}"), &path)?;
                let cols = p.u32s(&format!("columns_{c}"), &path)?;
                let vals = p.f32s(&format!("values_{c}"), &path)?;
                let total: u64 = widths.iter().sum();
                if cols.len() as u64 != total || vals.len() as u64 != total * n as u64 {
                    return Err(Error::verify(&path, "its panels do not add up"));
                }
                if cols.iter().any(|&j| j as usize >= n) {
                    return Err(Error::verify(&path, "a column index is out of range"));
                }
                let mut panels = Vec::with_capacity(widths.len());
                let mut at = 0usize;
                for w in widths {
                    let w = w as usize;
                    panels.push(Panel {
                        columns: cols[at..at + w].to_vec(),
                        values: vals[at * n..(at + w) * n].to_vec(),
                    });
                    at += w;
                }
                part.push(ChannelPart { panels });
            }
            assembly.add(i, part).map_err(|e| Error::verify(&path, e))?;
        }
        let f = ws.form_factors()?;
        check_shape(f.n, n)?;
        let t = assembly.finish(&f.values, &albedo)?;
        self.finish(ws, txn, n, t)
    }

    fn estimate_prepare(&self, state: &PlanState) -> u64 {
        // The factors of every channel (f32), held until they are written.
        let n2 = state.patches * state.patches;
        state.channels.max(1) * n2 * 4 + n2 * 2
    }

    fn estimate_shard(&self, state: &PlanState, index: usize, count: usize) -> u64 {
        let n = state.patches as usize;
        part_memory(n, state.channels.max(1) as usize, index, count)
    }

    fn estimate(&self, state: &mut PlanState) -> PlannedStage {
        let n = state.patches as usize;
        let channels = state.channels.max(1);
        // The form factors are already counted as resident by the plan.
        let bytes = memory_estimate(n, channels as usize, self.bounces) - (n * n) as u64 * 4;
        state.resident_bytes += GEMM_SCRATCH;
        PlannedStage {
            stage: "transport".into(),
            peak_bytes: bytes,
            output_bytes: channels * state.patches * state.patches * 4,
            notes: format!("{:?}, {channels} channel(s)", self.bounces),
        }
    }
}

impl TransportKnobs {
    /// Write S and build the stage's record (shared by `run` and the merge of shards).
    fn finish(
        &self,
        ws: &mut Workspace,
        txn: &mut BakeTransaction,
        n: usize,
        t: Transport,
    ) -> Result<StageRecord> {
        baked::transport::write(txn, &t.matrix)?;
        let mut rec = record("transport", &[baked::transport::FILE]);
        rec.report
            .insert("channels".into(), t.matrix.channels as f64);
        rec.report.insert("patches".into(), n as f64);
        rec.report.insert("products".into(), t.products as f64);
        for (c, k) in t.bounces.iter().enumerate() {
            rec.report.insert(format!("bounces_{c}"), *k as f64);
        }
        for (c, (lo, hi)) in t.spectral_bounds.iter().enumerate() {
            rec.report.insert(format!("spectral_radius_low_{c}"), *lo);
            rec.report.insert(format!("spectral_radius_high_{c}"), *hi);
        }
        for (c, (solver, err)) in t.solvers.iter().enumerate() {
            rec.facts
                .insert(format!("solver_{c}"), format!("{solver:?} LU"));
            rec.report
                .insert(format!("solver_error_estimate_{c}"), *err);
        }
        let max = t.matrix.data.iter().copied().fold(0f32, f32::max);
        rec.report.insert("max_entry".into(), max as f64);
        rec.facts.insert(
            "layout".into(),
            "[channels, n, n] f32 row-major; channels = 1 (grey: serves R, G, B) or 3 (R, G, B)"
                .into(),
        );
        rec.facts
            .insert("bounces".into(), format!("{:?}", self.bounces));
        ws.set_transport(t.matrix);
        Ok(rec)
    }
}

fn albedos(set: &crate::radiosity::PatchSet) -> Vec<[f32; 3]> {
    set.patches.iter().map(|p| p.albedo).collect()
}

fn check_shape(f_n: usize, n: usize) -> Result<()> {
    if f_n != n {
        return Err(Error::input(
            baked::form_factors::FILE,
            format!(
                "shape {:?} does not match the {n} patches of {}; re-run form_factors",
                [f_n, f_n],
                baked::patches::FILE
            ),
        ));
    }
    Ok(())
}

/// The solver and estimated error of channel `c` from the transport's prepared factors.
fn read_solver(p: &Mapped, c: usize) -> Result<(InfiniteSolver, f64)> {
    let solver = match p.u32s(&format!("solver_{c}"))?.first() {
        Some(0) => InfiniteSolver::Auto,
        Some(1) => InfiniteSolver::F32,
        Some(2) => InfiniteSolver::F64,
        other => return Err(Error::verify(p.path(), format!("unknown solver {other:?}"))),
    };
    let error = p
        .f64s(&format!("error_{c}"))?
        .first()
        .copied()
        .unwrap_or(f64::NAN);
    Ok((solver, error))
}

/// Channel `c`'s factors from the transport's prepared factors.
fn read_factors(p: &Mapped, c: usize, n: usize) -> Result<ChannelFactors> {
    let (solver, error) = read_solver(p, c)?;
    let perm = p.u64s(&format!("perm_{c}"))?;
    let bad = || {
        Error::verify(
            p.path(),
            format!("the factors of channel {c} are not {n} x {n}"),
        )
    };
    if perm.len() != n {
        return Err(bad());
    }
    let lu = format!("lu_{c}");
    let factor = if p.has(&lu, "f64") {
        InfiniteFactor::F64(Factored::from_parts(&p.f64s(&lu)?, &perm).ok_or_else(bad)?)
    } else {
        InfiniteFactor::F32(Factored::from_parts(&p.f32s(&lu)?, &perm).ok_or_else(bad)?)
    };
    Ok(ChannelFactors {
        factor,
        solver,
        error,
    })
}
