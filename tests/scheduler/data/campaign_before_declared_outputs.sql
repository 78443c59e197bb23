PRAGMA foreign_keys=OFF;
BEGIN TRANSACTION;
CREATE TABLE queue_meta(key TEXT PRIMARY KEY, value TEXT NOT NULL) STRICT;
INSERT INTO queue_meta VALUES('schema_version','2');
INSERT INTO queue_meta VALUES('campaign_id','779e56550f9f5781bab07625d057cee2');
CREATE TABLE sweeps(
  sweep_id TEXT PRIMARY KEY,
  job_kind TEXT NOT NULL,
  spec_json TEXT NOT NULL,
  spec_sha256 TEXT NOT NULL,
  submitted_at REAL NOT NULL,
  updated_at REAL NOT NULL,
  submits INTEGER NOT NULL DEFAULT 1
) STRICT;
INSERT INTO sweeps VALUES('old_drops','impact','{"axes":[{"name":"impact_speed_m_s","pointer":"/projectile/impact_speed_m_s","values":[0.5,0.75,1]}],"base":{"bed":{"dt_s":1e-05,"quench":{"interval_s":0.0005,"time_s":0.2},"relax_time_s":0.05,"seed":7,"settle":{"max_speed_m_s":0.005,"max_time_s":0.3,"rms_speed_m_s":0.0001},"settle_gravity_m_s2":9.81},"container":{"diameter_m":0.2,"fill_height_m":0.06},"dt_s":1e-05,"gravity_m_s2":9.81,"name":"tiny","projectile":{"impact_speed_m_s":0.5,"lateral_offset_max_grain_diameters":1,"seed":3,"vertical_offset_max_grain_diameters":0.5},"stop":{"max_time_s":0.5}},"description":"A campaign of the previous build (before outputs were declared): one bed, two drops, one of them finished.","max_attempts":3,"sweep":"old_drops"}','5cb3292a23e0351d460b7d583a7fa85a76607a40709c1a959d720082aa840a2f',1796585696.6663086413,1796585811.4496116638,2);
INSERT INTO sweeps VALUES('old_noop','noop','{"axes":[{"name":"gravity_m_s2","pointer":"/g","values":[1,2,3]}],"base":{"g":1.5,"sleep_s":0,"value":3},"job":"noop","sweep":"old_noop"}','189c2e4e9f4955d43159b595d2cd98c647dc8afee0f7bd5390c3c5f239ca52a9',1796585794.3719391823,1796585794.3719391823,1);
CREATE TABLE jobs(
  seq INTEGER PRIMARY KEY,
  job_id TEXT NOT NULL UNIQUE,
  kind TEXT NOT NULL CHECK(kind IN ('noop','bed','drop')),  -- the kinds registered when the database was made
  sweep_id TEXT NOT NULL REFERENCES sweeps(sweep_id),
  state TEXT NOT NULL CHECK(state IN ('waiting','queued','running','failed','done','dead')),
  priority INTEGER NOT NULL DEFAULT 0,
  deps_pending INTEGER NOT NULL DEFAULT 0,
  not_before REAL NOT NULL DEFAULT 0,
  attempts INTEGER NOT NULL DEFAULT 0,
  max_attempts INTEGER NOT NULL,
  releases INTEGER NOT NULL DEFAULT 0,  -- attempts given back (interrupted), not counted in attempts
  stalled_releases INTEGER NOT NULL DEFAULT 0,  -- the last releases in a row that saved no progress
  lease_owner TEXT,
  lease_token INTEGER NOT NULL DEFAULT 0,
  lease_expires REAL,
  heartbeat_at REAL,
  progress REAL,
  phase TEXT,
  detail TEXT,
  params_json TEXT NOT NULL,
  scenario_json TEXT NOT NULL,
  output_path TEXT,
  output_sha256 TEXT,
  output_bytes INTEGER,
  last_error TEXT,
  blocked_by TEXT,  -- a dead job that never ran because this dependency is dead (NULL otherwise)
  created_at REAL NOT NULL,
  started_at REAL,
  finished_at REAL
) STRICT;
INSERT INTO jobs VALUES(1,'dea7d7b1f0bcd40d826a','bed','old_drops','done',1,0,0.0,1,3,0,0,NULL,1,NULL,1796585769.712814331,1.0,'done',NULL,'{}','{"$as_written":{"bed":{"dt_s":1e-05,"quench":{"interval_s":0.0005,"time_s":0.2},"relax_time_s":0.05,"seed":7,"settle":{"max_speed_m_s":0.005,"max_time_s":0.3,"rms_speed_m_s":0.0001},"settle_gravity_m_s2":9.81},"container":{"diameter_m":0.2,"fill_height_m":0.06},"dt_s":1e-05,"gravity_m_s2":9.81,"name":"tiny","projectile":{"impact_speed_m_s":0.5,"lateral_offset_max_grain_diameters":1,"seed":3,"vertical_offset_max_grain_diameters":0.5},"stop":{"max_time_s":0.5}},"$validated_by":"0.1.0+1cdff39b58ea-dirty schema:29332d9a61f7","at_rest":{"rms_speed_fraction":0.001,"surface_speed_fraction":0.01},"bed":{"dt_s":1e-05,"gravity_ramp_s":0.1,"overfill_factor":1.15,"packing_fraction":0.6,"quench":{"interval_s":0.0005,"time_s":0.2},"relax_time_s":0.05,"seed":7,"settle":{"check_interval_s":0.001,"max_speed_m_s":0.005,"max_time_s":0.3,"min_roll_vel_m_s":1e-06,"rms_speed_m_s":0.0001},"settle_gravity_m_s2":9.81},"contact":{"clamp_normal":false,"composition":"explicit_pair","law":"hertz","pairs":{"grain-grain":{},"grain-projectile":{},"grain-wall":{"cor_normal":0.5,"mu_static":0.45},"projectile-wall":{"cor_normal":0.5,"mu_static":0.45}},"rolling_model":"sunday"},"container":{"diameter_m":0.2,"fill_height_m":0.06},"description":"","dt_s":1e-05,"grains":{"density_kg_m3":2480,"diameter_m":0.01,"diameter_spread_m":0.0005},"gravity_m_s2":9.81,"integrator":"semi_implicit_euler","materials":{"grain":{"cor_normal":0.9,"cor_tangential":1.0,"kn_N_m":0,"kt_N_m":0,"mu_rolling":0.09,"mu_static":0.16,"mu_twisting":0.01,"poisson_ratio":0.24,"shape_beta":0.05,"young_modulus_Pa":700000000.0},"projectile":{"cor_normal":0.9,"cor_tangential":1.0,"kn_N_m":0,"kt_N_m":0,"mu_rolling":0.09,"mu_static":0.16,"mu_twisting":0.01,"poisson_ratio":0.24,"shape_beta":0.05,"young_modulus_Pa":700000000.0},"wall":{"cor_normal":0.5,"cor_tangential":1.0,"kn_N_m":0,"kt_N_m":0,"mu_rolling":0.09,"mu_static":0.45,"mu_twisting":0.01,"poisson_ratio":0.24,"shape_beta":0.05,"young_modulus_Pa":700000000.0}},"name":"tiny","output":{"end_speed_fraction":0.1,"end_threshold_g":0.1,"filter_cutoff_hz":500,"sample_rate_hz":10000,"snapshot_interval_s":0},"projectile":{"diameter_m":0.1,"impact_speed_m_s":0.5,"lateral_offset_max_grain_diameters":1,"mass_kg":1.0,"seed":3,"site_draw":"point","start_gap_m":0.005,"vertical_offset_max_grain_diameters":0.5},"rolling_threshold":{"min_roll_vel_at_9_81_m_s":0.0001},"stop":{"hold_time_sqrt_D_g":0.05,"max_time_s":0.5,"max_time_sqrt_D_g":10,"speed_sqrt_gD":0.001},"threads":0}','beds/dea7d7b1f0bcd40d826a.a1.h5','562bc3eb41beb340b700745d525b93d2285aeaa70dbeb53a72991edeacf5af64',189478,NULL,NULL,1796585696.6663086413,1796585696.8496546745,1796585771.62387228);
INSERT INTO jobs VALUES(2,'a8de2a05413033c01fa5','drop','old_drops','done',0,0,0.0,1,3,0,0,NULL,1,NULL,1796585793.8879885673,1.0,'done',NULL,'{"impact_speed_m_s":0.5}','{"$as_written":{"bed":{"dt_s":1e-05,"quench":{"interval_s":0.0005,"time_s":0.2},"relax_time_s":0.05,"seed":7,"settle":{"max_speed_m_s":0.005,"max_time_s":0.3,"rms_speed_m_s":0.0001},"settle_gravity_m_s2":9.81},"container":{"diameter_m":0.2,"fill_height_m":0.06},"dt_s":1e-05,"gravity_m_s2":9.81,"name":"tiny","projectile":{"impact_speed_m_s":0.5,"lateral_offset_max_grain_diameters":1,"seed":3,"vertical_offset_max_grain_diameters":0.5},"stop":{"max_time_s":0.5}},"$validated_by":"0.1.0+1cdff39b58ea-dirty schema:29332d9a61f7","at_rest":{"rms_speed_fraction":0.001,"surface_speed_fraction":0.01},"bed":{"dt_s":1e-05,"gravity_ramp_s":0.1,"overfill_factor":1.15,"packing_fraction":0.6,"quench":{"interval_s":0.0005,"time_s":0.2},"relax_time_s":0.05,"seed":7,"settle":{"check_interval_s":0.001,"max_speed_m_s":0.005,"max_time_s":0.3,"min_roll_vel_m_s":1e-06,"rms_speed_m_s":0.0001},"settle_gravity_m_s2":9.81},"contact":{"clamp_normal":false,"composition":"explicit_pair","law":"hertz","pairs":{"grain-grain":{},"grain-projectile":{},"grain-wall":{"cor_normal":0.5,"mu_static":0.45},"projectile-wall":{"cor_normal":0.5,"mu_static":0.45}},"rolling_model":"sunday"},"container":{"diameter_m":0.2,"fill_height_m":0.06},"description":"","dt_s":1e-05,"grains":{"density_kg_m3":2480,"diameter_m":0.01,"diameter_spread_m":0.0005},"gravity_m_s2":9.81,"integrator":"semi_implicit_euler","materials":{"grain":{"cor_normal":0.9,"cor_tangential":1.0,"kn_N_m":0,"kt_N_m":0,"mu_rolling":0.09,"mu_static":0.16,"mu_twisting":0.01,"poisson_ratio":0.24,"shape_beta":0.05,"young_modulus_Pa":700000000.0},"projectile":{"cor_normal":0.9,"cor_tangential":1.0,"kn_N_m":0,"kt_N_m":0,"mu_rolling":0.09,"mu_static":0.16,"mu_twisting":0.01,"poisson_ratio":0.24,"shape_beta":0.05,"young_modulus_Pa":700000000.0},"wall":{"cor_normal":0.5,"cor_tangential":1.0,"kn_N_m":0,"kt_N_m":0,"mu_rolling":0.09,"mu_static":0.45,"mu_twisting":0.01,"poisson_ratio":0.24,"shape_beta":0.05,"young_modulus_Pa":700000000.0}},"name":"tiny","output":{"end_speed_fraction":0.1,"end_threshold_g":0.1,"filter_cutoff_hz":500,"sample_rate_hz":10000,"snapshot_interval_s":0},"projectile":{"diameter_m":0.1,"impact_speed_m_s":0.5,"lateral_offset_max_grain_diameters":1,"mass_kg":1.0,"seed":3,"site_draw":"point","start_gap_m":0.005,"vertical_offset_max_grain_diameters":0.5},"rolling_threshold":{"min_roll_vel_at_9_81_m_s":0.0001},"stop":{"hold_time_sqrt_D_g":0.05,"max_time_s":0.5,"max_time_sqrt_D_g":10,"speed_sqrt_gD":0.001},"threads":0}','traces/a8de2a05413033c01fa5.a1.h5','da221323944010af7eedef279a289112d4c7534c613b033e0ff0d4d617d0893e',153067,NULL,NULL,1796585696.6663086413,1796585771.624456644,1796585794.1517651081);
INSERT INTO jobs VALUES(3,'0c06e462015d8451596d','drop','old_drops','done',0,0,0.0,1,3,0,0,NULL,1,NULL,1796585802.5703191757,1.0,'done',NULL,'{"impact_speed_m_s":0.75}','{"$as_written":{"bed":{"dt_s":1e-05,"quench":{"interval_s":0.0005,"time_s":0.2},"relax_time_s":0.05,"seed":7,"settle":{"max_speed_m_s":0.005,"max_time_s":0.3,"rms_speed_m_s":0.0001},"settle_gravity_m_s2":9.81},"container":{"diameter_m":0.2,"fill_height_m":0.06},"dt_s":1e-05,"gravity_m_s2":9.81,"name":"tiny","projectile":{"impact_speed_m_s":0.75,"lateral_offset_max_grain_diameters":1,"seed":3,"vertical_offset_max_grain_diameters":0.5},"stop":{"max_time_s":0.5}},"$validated_by":"0.1.0+1cdff39b58ea-dirty schema:29332d9a61f7","at_rest":{"rms_speed_fraction":0.001,"surface_speed_fraction":0.01},"bed":{"dt_s":1e-05,"gravity_ramp_s":0.1,"overfill_factor":1.15,"packing_fraction":0.6,"quench":{"interval_s":0.0005,"time_s":0.2},"relax_time_s":0.05,"seed":7,"settle":{"check_interval_s":0.001,"max_speed_m_s":0.005,"max_time_s":0.3,"min_roll_vel_m_s":1e-06,"rms_speed_m_s":0.0001},"settle_gravity_m_s2":9.81},"contact":{"clamp_normal":false,"composition":"explicit_pair","law":"hertz","pairs":{"grain-grain":{},"grain-projectile":{},"grain-wall":{"cor_normal":0.5,"mu_static":0.45},"projectile-wall":{"cor_normal":0.5,"mu_static":0.45}},"rolling_model":"sunday"},"container":{"diameter_m":0.2,"fill_height_m":0.06},"description":"","dt_s":1e-05,"grains":{"density_kg_m3":2480,"diameter_m":0.01,"diameter_spread_m":0.0005},"gravity_m_s2":9.81,"integrator":"semi_implicit_euler","materials":{"grain":{"cor_normal":0.9,"cor_tangential":1.0,"kn_N_m":0,"kt_N_m":0,"mu_rolling":0.09,"mu_static":0.16,"mu_twisting":0.01,"poisson_ratio":0.24,"shape_beta":0.05,"young_modulus_Pa":700000000.0},"projectile":{"cor_normal":0.9,"cor_tangential":1.0,"kn_N_m":0,"kt_N_m":0,"mu_rolling":0.09,"mu_static":0.16,"mu_twisting":0.01,"poisson_ratio":0.24,"shape_beta":0.05,"young_modulus_Pa":700000000.0},"wall":{"cor_normal":0.5,"cor_tangential":1.0,"kn_N_m":0,"kt_N_m":0,"mu_rolling":0.09,"mu_static":0.45,"mu_twisting":0.01,"poisson_ratio":0.24,"shape_beta":0.05,"young_modulus_Pa":700000000.0}},"name":"tiny","output":{"end_speed_fraction":0.1,"end_threshold_g":0.1,"filter_cutoff_hz":500,"sample_rate_hz":10000,"snapshot_interval_s":0},"projectile":{"diameter_m":0.1,"impact_speed_m_s":0.75,"lateral_offset_max_grain_diameters":1,"mass_kg":1.0,"seed":3,"site_draw":"point","start_gap_m":0.005,"vertical_offset_max_grain_diameters":0.5},"rolling_threshold":{"min_roll_vel_at_9_81_m_s":0.0001},"stop":{"hold_time_sqrt_D_g":0.05,"max_time_s":0.5,"max_time_sqrt_D_g":10,"speed_sqrt_gD":0.001},"threads":0}','traces/0c06e462015d8451596d.a1.h5','2edc3f4b8e17bc1d7c96fc2f899bbd41e0bda49a080c3d9d7f66d616604ec3a7',143075,NULL,NULL,1796585696.6663086413,1796585794.4972760677,1796585802.9392809867);
INSERT INTO jobs VALUES(4,'62bf6192a7cba6d2937c','noop','old_noop','done',0,0,0.0,1,3,0,0,NULL,1,NULL,1796585802.940915346,1.0,'done',NULL,'{"gravity_m_s2":1}','{"g":1,"sleep_s":0,"value":3}','noop/62bf6192a7cba6d2937c.a1.json','b146b07d99c37e9803abeac717dea17012cc9694fd9d3e47eb357a990d8049b1',45,NULL,NULL,1796585794.3719391823,1796585802.9397959709,1796585802.942911148);
INSERT INTO jobs VALUES(5,'f0b610a1fda30471dc81','noop','old_noop','queued',0,0,0.0,0,3,0,0,NULL,0,NULL,NULL,NULL,NULL,NULL,'{"gravity_m_s2":2}','{"g":2,"sleep_s":0,"value":3}',NULL,NULL,NULL,NULL,NULL,1796585794.3719391823,NULL,NULL);
INSERT INTO jobs VALUES(6,'82c42a5937fc69cd9305','noop','old_noop','queued',0,0,0.0,0,3,0,0,NULL,0,NULL,NULL,NULL,NULL,NULL,'{"gravity_m_s2":3}','{"g":3,"sleep_s":0,"value":3}',NULL,NULL,NULL,NULL,NULL,1796585794.3719391823,NULL,NULL);
INSERT INTO jobs VALUES(7,'e61acfbc5108c2b57008','drop','old_drops','queued',0,0,0.0,0,3,0,0,NULL,0,NULL,NULL,NULL,NULL,NULL,'{"impact_speed_m_s":1}','{"$as_written":{"bed":{"dt_s":1e-05,"quench":{"interval_s":0.0005,"time_s":0.2},"relax_time_s":0.05,"seed":7,"settle":{"max_speed_m_s":0.005,"max_time_s":0.3,"rms_speed_m_s":0.0001},"settle_gravity_m_s2":9.81},"container":{"diameter_m":0.2,"fill_height_m":0.06},"dt_s":1e-05,"gravity_m_s2":9.81,"name":"tiny","projectile":{"impact_speed_m_s":1,"lateral_offset_max_grain_diameters":1,"seed":3,"vertical_offset_max_grain_diameters":0.5},"stop":{"max_time_s":0.5}},"$validated_by":"0.1.0+1cdff39b58ea-dirty schema:29332d9a61f7","at_rest":{"rms_speed_fraction":0.001,"surface_speed_fraction":0.01},"bed":{"dt_s":1e-05,"gravity_ramp_s":0.1,"overfill_factor":1.15,"packing_fraction":0.6,"quench":{"interval_s":0.0005,"time_s":0.2},"relax_time_s":0.05,"seed":7,"settle":{"check_interval_s":0.001,"max_speed_m_s":0.005,"max_time_s":0.3,"min_roll_vel_m_s":1e-06,"rms_speed_m_s":0.0001},"settle_gravity_m_s2":9.81},"contact":{"clamp_normal":false,"composition":"explicit_pair","law":"hertz","pairs":{"grain-grain":{},"grain-projectile":{},"grain-wall":{"cor_normal":0.5,"mu_static":0.45},"projectile-wall":{"cor_normal":0.5,"mu_static":0.45}},"rolling_model":"sunday"},"container":{"diameter_m":0.2,"fill_height_m":0.06},"description":"","dt_s":1e-05,"grains":{"density_kg_m3":2480,"diameter_m":0.01,"diameter_spread_m":0.0005},"gravity_m_s2":9.81,"integrator":"semi_implicit_euler","materials":{"grain":{"cor_normal":0.9,"cor_tangential":1.0,"kn_N_m":0,"kt_N_m":0,"mu_rolling":0.09,"mu_static":0.16,"mu_twisting":0.01,"poisson_ratio":0.24,"shape_beta":0.05,"young_modulus_Pa":700000000.0},"projectile":{"cor_normal":0.9,"cor_tangential":1.0,"kn_N_m":0,"kt_N_m":0,"mu_rolling":0.09,"mu_static":0.16,"mu_twisting":0.01,"poisson_ratio":0.24,"shape_beta":0.05,"young_modulus_Pa":700000000.0},"wall":{"cor_normal":0.5,"cor_tangential":1.0,"kn_N_m":0,"kt_N_m":0,"mu_rolling":0.09,"mu_static":0.45,"mu_twisting":0.01,"poisson_ratio":0.24,"shape_beta":0.05,"young_modulus_Pa":700000000.0}},"name":"tiny","output":{"end_speed_fraction":0.1,"end_threshold_g":0.1,"filter_cutoff_hz":500,"sample_rate_hz":10000,"snapshot_interval_s":0},"projectile":{"diameter_m":0.1,"impact_speed_m_s":1,"lateral_offset_max_grain_diameters":1,"mass_kg":1.0,"seed":3,"site_draw":"point","start_gap_m":0.005,"vertical_offset_max_grain_diameters":0.5},"rolling_threshold":{"min_roll_vel_at_9_81_m_s":0.0001},"stop":{"hold_time_sqrt_D_g":0.05,"max_time_s":0.5,"max_time_sqrt_D_g":10,"speed_sqrt_gD":0.001},"threads":0}',NULL,NULL,NULL,NULL,NULL,1796585811.4496116638,NULL,NULL);
CREATE TABLE job_deps(
  job_id TEXT NOT NULL REFERENCES jobs(job_id),
  dep_id TEXT NOT NULL REFERENCES jobs(job_id),
  PRIMARY KEY(job_id, dep_id)
) STRICT, WITHOUT ROWID;
INSERT INTO job_deps VALUES('0c06e462015d8451596d','dea7d7b1f0bcd40d826a');
INSERT INTO job_deps VALUES('a8de2a05413033c01fa5','dea7d7b1f0bcd40d826a');
INSERT INTO job_deps VALUES('e61acfbc5108c2b57008','dea7d7b1f0bcd40d826a');
CREATE TABLE sweep_jobs(
  sweep_id TEXT NOT NULL REFERENCES sweeps(sweep_id),
  job_id TEXT NOT NULL REFERENCES jobs(job_id),
  shared INTEGER NOT NULL DEFAULT 0,  -- 1: the job was created by another sweep (jobs.sweep_id)
  PRIMARY KEY(sweep_id, job_id)
) STRICT, WITHOUT ROWID;
INSERT INTO sweep_jobs VALUES('old_drops','0c06e462015d8451596d',0);
INSERT INTO sweep_jobs VALUES('old_drops','a8de2a05413033c01fa5',0);
INSERT INTO sweep_jobs VALUES('old_drops','dea7d7b1f0bcd40d826a',0);
INSERT INTO sweep_jobs VALUES('old_drops','e61acfbc5108c2b57008',0);
INSERT INTO sweep_jobs VALUES('old_noop','62bf6192a7cba6d2937c',0);
INSERT INTO sweep_jobs VALUES('old_noop','82c42a5937fc69cd9305',0);
INSERT INTO sweep_jobs VALUES('old_noop','f0b610a1fda30471dc81',0);
CREATE TABLE attempts(
  attempt_id INTEGER PRIMARY KEY,
  job_id TEXT NOT NULL REFERENCES jobs(job_id),
  attempt INTEGER NOT NULL,
  lease_token INTEGER NOT NULL,
  kind TEXT NOT NULL,
  worker TEXT NOT NULL,
  host TEXT NOT NULL,
  pid INTEGER NOT NULL,
  threads INTEGER NOT NULL,
  code_version TEXT NOT NULL,
  started_at REAL NOT NULL,
  ended_at REAL,
  runtime_s REAL,
  outcome TEXT NOT NULL CHECK(outcome IN ('running','done','failed','dead','lost','released')),
  exit_code INTEGER,
  error TEXT,
  output_path TEXT,
  report_json TEXT
) STRICT;
INSERT INTO attempts VALUES(1,'dea7d7b1f0bcd40d826a',1,1,'bed','vm:27818:1796585696849','vm',27818,1,'0.1.0+1cdff39b58ea-dirty',1796585696.8496546745,1796585771.62387228,74.774217605590820312,'done',0,NULL,'beds/dea7d7b1f0bcd40d826a.a1.h5','{"at_rest_for_impacts_above_m_s":0.10168193851287373,"bulk_density_kg_m3":1374.3085950051586,"checkpoint_resumes":0,"checkpoints_written":0,"dt_s":1e-05,"grains_kept":2034,"grains_placed":2484,"max_speed_m_s":0.0010168193851287372,"max_surface_speed_m_s":0.0010168193851287372,"quench_time_s":0.2,"relax_end":"criteria","relax_time_s":0.0509999999997679,"resumed_at_s":null,"rms_speed_m_s":7.98024408885377e-05,"settle_end":"time_cap","settle_time_s":0.30000000000015925,"settled":false,"steps":55100,"surface_grains":675,"surface_height_m":0.06129891721511002,"surface_relax_s":0,"threads":1,"wall_s":74.743548083,"wall_time_s":74.651147623}');
INSERT INTO attempts VALUES(2,'a8de2a05413033c01fa5',1,1,'drop','vm:27818:1796585696849','vm',27818,1,'0.1.0+1cdff39b58ea-dirty',1796585771.624456644,1796585794.1517651081,22.527308464050292968,'done',0,NULL,'traces/a8de2a05413033c01fa5.a1.h5','{"threads":1,"wall_s":22.512480226}');
INSERT INTO attempts VALUES(3,'0c06e462015d8451596d',1,1,'drop','vm:27985:1796585794497','vm',27985,2,'0.1.0+1cdff39b58ea-dirty',1796585794.4972760677,1796585802.9392809867,8.4420049190521240234,'done',0,NULL,'traces/0c06e462015d8451596d.a1.h5','{"threads":2,"wall_s":8.407339063}');
INSERT INTO attempts VALUES(4,'62bf6192a7cba6d2937c',1,1,'noop','vm:27985:1796585794497','vm',27985,2,'0.1.0+1cdff39b58ea-dirty',1796585802.9397959709,1796585802.942911148,0.003115177154541015625,'done',0,NULL,'noop/62bf6192a7cba6d2937c.a1.json','{"threads":2,"wall_s":0.002538861}');
CREATE TABLE results(
  job_id TEXT PRIMARY KEY REFERENCES jobs(job_id),
  sweep TEXT NOT NULL,
  kind TEXT NOT NULL,
  bed_job_id TEXT,
  attempt INTEGER NOT NULL,
  trace_path TEXT,
  trace_sha256 TEXT,
  trace_bytes INTEGER,
  runtime_s REAL,
  finished_at REAL,
  code_version TEXT
, "impact_speed_m_s" REAL, "apeak_m_s2" REAL, "checkpoint_resumes" INTEGER, "checkpoints_written" INTEGER, "cutoff_hz" REAL, "depth_at_end_m" REAL, "dt_s" REAL, "duration_to_rest_s" REAL, "end_hold_s" REAL, "final_depth_below_surface_m" REAL, "final_depth_m" REAL, "first_contact_s" REAL, "first_touch_height_above_surface_m" REAL, "grains" INTEGER, "grains_spilled_over_rim" INTEGER, "gravity_m_s2" REAL, "lateral_offset_m" REAL, "max_depth_m" REAL, "note" TEXT, "rebound" INTEGER, "release_height_above_surface_m" REAL, "release_speed_m_s" REAL, "rest_time_s" REAL, "sample_rate_hz" REAL, "simulated_time_s" REAL, "start_depth_m" REAL, "steps" INTEGER, "stopped" INTEGER, "surface_height_m" REAL, "t_end_s" REAL, "t_start_s" REAL, "threads" INTEGER, "tstop_s" REAL, "vc_m_s" REAL, "wall_time_s" REAL, "zstop_m" REAL, "zstop_surface_m" REAL, "noop_value" INTEGER, "sleep_s" REAL) STRICT;
INSERT INTO results VALUES('a8de2a05413033c01fa5','old_drops','drop','dea7d7b1f0bcd40d826a',1,'traces/a8de2a05413033c01fa5.a1.h5','da221323944010af7eedef279a289112d4c7534c613b033e0ff0d4d617d0893e',153067,22.527308464050292968,1796585794.1517651081,'0.1.0+1cdff39b58ea-dirty',0.5,19.380583114842213632,0,0,500.0,0.030117748735721299596,1.0000000000000000817e-05,0.14310000000002570663,0.0020000000000000000416,0.027555436383237888464,0.03016843195618054696,0.017999999999999436589,0.0025770508028137434353,2034,0,9.8100000000000004973,0.0076229514021986938265,0.027555436383237888464,'',0,0.0099793210800046272535,0.32367801464034412495,0.16100000000002515077,10000.0,0.16590000000002513846,-0.0026129955729426584953,16590,1,0.06129891721511002145,0.13001235556961218686,0.017899999999999440664,1,0.11211235556961274273,0.49927701464032597789,22.431932627999998431,0.03016843195618054696,0.027555436383237888464,NULL,NULL);
INSERT INTO results VALUES('0c06e462015d8451596d','old_drops','drop','dea7d7b1f0bcd40d826a',1,'traces/0c06e462015d8451596d.a1.h5','2edc3f4b8e17bc1d7c96fc2f899bbd41e0bda49a080c3d9d7f66d616604ec3a7',143075,8.4420049190521240234,1796585802.9392809867,'0.1.0+1cdff39b58ea-dirty',0.75,23.85558863452918743,0,0,500.0,0.033513959366941993567,1.0000000000000000817e-05,0.13670000000001036877,0.0020000000000000000416,0.030102059190507027275,0.033563920140138259196,0.0093999999999997852634,0.0034577014678969647532,2034,0,9.8100000000000004973,0.0096913817521489115103,0.030102059190507027275,'',0,0.010012522176299956666,0.65870662491061482413,0.14600000000001014943,10000.0,0.15090000000001013713,-0.0034618609496312319206,15090,1,0.06129891721511002145,0.11710519697289455132,0.0092999999999997893379,2,0.10780519697289475677,0.74993962491060539576,8.3664279290000003186,0.033563920140138259196,0.030102059190507027275,NULL,NULL);
INSERT INTO results VALUES('62bf6192a7cba6d2937c','old_noop','noop',NULL,1,'noop/62bf6192a7cba6d2937c.a1.json','b146b07d99c37e9803abeac717dea17012cc9694fd9d3e47eb357a990d8049b1',45,0.003115177154541015625,1796585802.942911148,'0.1.0+1cdff39b58ea-dirty',NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,1.0,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,NULL,3,0.0);
CREATE TABLE results_columns(
  name TEXT PRIMARY KEY,
  role TEXT NOT NULL CHECK(role IN ('param','metric')),
  sql_type TEXT NOT NULL,
  position INTEGER NOT NULL
) STRICT;
INSERT INTO results_columns VALUES('impact_speed_m_s','param','REAL',1);
INSERT INTO results_columns VALUES('apeak_m_s2','metric','REAL',2);
INSERT INTO results_columns VALUES('checkpoint_resumes','metric','INTEGER',3);
INSERT INTO results_columns VALUES('checkpoints_written','metric','INTEGER',4);
INSERT INTO results_columns VALUES('cutoff_hz','metric','REAL',5);
INSERT INTO results_columns VALUES('depth_at_end_m','metric','REAL',6);
INSERT INTO results_columns VALUES('dt_s','metric','REAL',7);
INSERT INTO results_columns VALUES('duration_to_rest_s','metric','REAL',8);
INSERT INTO results_columns VALUES('end_hold_s','metric','REAL',9);
INSERT INTO results_columns VALUES('final_depth_below_surface_m','metric','REAL',10);
INSERT INTO results_columns VALUES('final_depth_m','metric','REAL',11);
INSERT INTO results_columns VALUES('first_contact_s','metric','REAL',12);
INSERT INTO results_columns VALUES('first_touch_height_above_surface_m','metric','REAL',13);
INSERT INTO results_columns VALUES('grains','metric','INTEGER',14);
INSERT INTO results_columns VALUES('grains_spilled_over_rim','metric','INTEGER',15);
INSERT INTO results_columns VALUES('gravity_m_s2','metric','REAL',16);
INSERT INTO results_columns VALUES('lateral_offset_m','metric','REAL',17);
INSERT INTO results_columns VALUES('max_depth_m','metric','REAL',18);
INSERT INTO results_columns VALUES('note','metric','TEXT',19);
INSERT INTO results_columns VALUES('rebound','metric','INTEGER',20);
INSERT INTO results_columns VALUES('release_height_above_surface_m','metric','REAL',21);
INSERT INTO results_columns VALUES('release_speed_m_s','metric','REAL',22);
INSERT INTO results_columns VALUES('rest_time_s','metric','REAL',23);
INSERT INTO results_columns VALUES('sample_rate_hz','metric','REAL',24);
INSERT INTO results_columns VALUES('simulated_time_s','metric','REAL',25);
INSERT INTO results_columns VALUES('start_depth_m','metric','REAL',26);
INSERT INTO results_columns VALUES('steps','metric','INTEGER',27);
INSERT INTO results_columns VALUES('stopped','metric','INTEGER',28);
INSERT INTO results_columns VALUES('surface_height_m','metric','REAL',29);
INSERT INTO results_columns VALUES('t_end_s','metric','REAL',30);
INSERT INTO results_columns VALUES('t_start_s','metric','REAL',31);
INSERT INTO results_columns VALUES('threads','metric','INTEGER',32);
INSERT INTO results_columns VALUES('tstop_s','metric','REAL',33);
INSERT INTO results_columns VALUES('vc_m_s','metric','REAL',34);
INSERT INTO results_columns VALUES('wall_time_s','metric','REAL',35);
INSERT INTO results_columns VALUES('zstop_m','metric','REAL',36);
INSERT INTO results_columns VALUES('zstop_surface_m','metric','REAL',37);
INSERT INTO results_columns VALUES('noop_value','metric','INTEGER',38);
INSERT INTO results_columns VALUES('sleep_s','metric','REAL',39);
CREATE INDEX jobs_claim ON jobs(state, priority DESC, seq);
CREATE INDEX jobs_lease ON jobs(state, lease_expires);
CREATE INDEX jobs_backoff ON jobs(state, not_before);
CREATE INDEX jobs_sweep_state ON jobs(sweep_id, kind, state);
CREATE INDEX job_deps_dep ON job_deps(dep_id);
CREATE INDEX sweep_jobs_job ON sweep_jobs(job_id);
CREATE INDEX sweep_jobs_shared ON sweep_jobs(shared) WHERE shared=1;
CREATE INDEX attempts_job ON attempts(job_id, outcome);
CREATE INDEX attempts_runtime ON attempts(kind, outcome, runtime_s);
COMMIT;
