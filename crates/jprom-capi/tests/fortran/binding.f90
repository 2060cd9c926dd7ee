! The Fortran binding (fortran/jprom.f90) beyond the examples: every wrapper of module jprom is
! called on the examples' two-node model and checked against another route to the same
! number (dense vs 1-based CSC model, a sweep point vs the solution copied out of it, saved vs
! loaded, an FE model built from the same matrices vs the model itself), and wrong 1-based
! indices come back as statuses with a message. Prints "ok <what>" per check, "version <v>",
! and "all checks passed" at the end; stops with code 1 at the first failure. Argument: a
! directory for the saved files.
program binding
  use, intrinsic :: iso_c_binding
  use jprom
  implicit none
  integer, parameter :: n = 6
  real(c_double) :: mass(n, n), stiffness(n, n), frame(3, 3), fc(n), fs(n), zeros(n)
  type(c_ptr) :: model, csc, copy, loaded, sol, sol2, sweep, sweep2, basis, basis2, rsweep, fe, reduced, rsol, full
  type(c_ptr) :: asweep, abasis
  type(jprom_hbm_options) :: opts
  type(jprom_sweep_options) :: band
  type(jprom_jp_options) :: jp_opts
  character(len=512) :: msg
  character(len=400) :: dir
  integer :: d, i, k, s, handles0, handles, nd, nc, no, hh, no2, nc2, npts, npts2, it, ns, kind
  integer :: sizes(0:3), sizes2(0:3), reason, cend
  integer, allocatable :: states(:), colptr(:), rowind(:)
  real(c_double), allocatable :: mvals(:), kvals(:)
  real(c_double) :: a1(2), a2(2), omega, omega2, coeffs(2, 7), amp, res, energy(1), e(0:3), estar, alpha, value, wb, wa, judged
  real(c_double) :: w0err, judged_i, judged_worst
  character(len=512) :: trust_why
  integer :: na, ip
  integer(c_size_t) :: budget
  integer(c_int64_t) :: node_rows(6, 3)
  real(c_double) :: mass9(9, 9), stiffness9(9, 9)
  logical :: reached, repro, swept, trusted
  character(len=200) :: why
  type(c_ptr) :: duffing, dsweep
  type(jprom_hbm_options) :: dopts
  type(jprom_sweep_options) :: dband
  integer :: nev, ngap, ekind, eafter, eafter2
  real(c_double) :: ew, ew2, etol, eamp

  call get_command_argument(1, dir)
  if (dir == '') dir = '.'
  mass = 0; stiffness = 0
  do d = 1, 3
    mass(d, d) = 1; mass(3 + d, 3 + d) = 1
    stiffness(d, d) = 2.0d4; stiffness(3 + d, 3 + d) = 1.0d4
    stiffness(d, 3 + d) = -1.0d4; stiffness(3 + d, d) = -1.0d4
  end do
  frame = 0; frame(1, 1) = 1; frame(2, 2) = 1; frame(3, 3) = 1
  fc = 0; fc(1) = 5; fs = 0; zeros = 0

  ! ---- errors, version, diagnostics ----
  write (*, '(a,a)') 'version ', jp_version()
  call check(jp_status_name(JPROM_BAD_SIZE) == 'JPROM_BAD_SIZE' .and. jp_status_name(JPROM_OK) == 'JPROM_OK', &
             'jp_status_name')
  call ok(jp_set_memory_budget(123456789_c_size_t), 'jp_set_memory_budget')
  call ok(jp_memory_budget(budget), 'jp_memory_budget')
  call check(budget == 123456789_c_size_t, 'memory budget reads back')
  call ok(jp_set_memory_budget(0_c_size_t), 'jp_set_memory_budget(0)')
  call ok(jp_memory_budget(budget), 'jp_memory_budget')
  call check(budget > 123456789_c_size_t, 'memory budget default restored')
  call ok(jp_set_reproducible(.true.), 'jp_set_reproducible(.true.)')
  call ok(jp_reproducible(repro), 'jp_reproducible')
  call check(repro, 'reproducible kernels read back')
  call ok(jp_set_reproducible(.false.), 'jp_set_reproducible(.false.)')
  call ok(jp_reproducible(repro), 'jp_reproducible')
  call check(.not. repro, 'default kernels restored')
  call ok(jp_live_handle_count(handles0), 'jp_live_handle_count')

  ! ---- models: dense, CSC (1-based), clone, sizes ----
  call ok(jp_model_new(mass, stiffness, model, msg), 'jp_model_new')
  call to_csc(mass, colptr, rowind, mvals)
  deallocate (colptr, rowind)
  call to_csc(stiffness, colptr, rowind, kvals)
  ! the mass pattern is the diagonal: its own colptr/rowind
  call ok(jp_model_new_csc(n, [(i, i = 1, n + 1)], [(i, i = 1, n)], [(1.0d0, i = 1, n)], colptr, rowind, kvals, &
                           csc, msg), 'jp_model_new_csc')
  do i = 1, 2
    if (i == 1) copy = model
    if (i == 2) copy = csc
    call ok(jp_add_ground_contact(copy, [4, 5, 6], frame, 3.0d4, 3.0d4, 5.0d4, 0.5d0, 20.0d0, msg), 'contact')
    call ok(jp_set_damping(copy, 0.0d0, 1.0d-4, msg), 'jp_set_damping')
    call ok(jp_set_first_harmonic_force(copy, fc, fs, msg), 'jp_set_first_harmonic_force')
    call ok(jp_set_outputs(copy, [1, 4], msg), 'jp_set_outputs')
    call ok(jp_model_validate(copy, msg), 'jp_model_validate')
  end do
  call ok(jp_model_sizes(model, nd, nc, no, msg), 'jp_model_sizes')
  call check(nd == 6 .and. nc == 1 .and. no == 2, 'jp_model_sizes: 6 DoFs, 1 contact, 2 outputs')
  call check(jp_model_new_csc(n, [1, 2], [1], [1.0d0], colptr, rowind, kvals, copy, msg) == JPROM_BAD_SIZE .and. &
             msg /= '', 'jp_model_new_csc refuses a short colptr')

  call jp_default_options(opts, band)
  call check(band%struct_size == c_sizeof(band) .and. band%max_angle > 0, 'jp_default_options fills the version-2 sweep options')
  opts%harmonics = 3
  band%omega_start = 60; band%omega_end = 160

  ! ---- solutions ----
  call ok(jp_solve_point(model, 100.0d0, opts, sol, msg), 'jp_solve_point')
  call ok(jp_solve_point(csc, 100.0d0, opts, sol2, msg), 'jp_solve_point (CSC model)')
  call ok(jp_solution_amplitude(sol, 1, 1, a1(1)), 'jp_solution_amplitude')
  call ok(jp_solution_amplitude(sol2, 1, 1, a2(1)), 'jp_solution_amplitude')
  call check(abs(a1(1) - a2(1)) <= 1d-12 * a1(1) .and. a1(1) > 0, 'dense and 1-based CSC models: same solution')
  s = jp_solution_free(sol2)
  call ok(jp_solution_omega(sol, omega), 'jp_solution_omega')
  call check(omega == 100.0d0, 'solution omega')
  call ok(jp_solution_sizes(sol, hh, no2, nc2), 'jp_solution_sizes')
  call check(hh == 3 .and. no2 == 2 .and. nc2 == 1, 'jp_solution_sizes: H 3, 2 outputs, 1 contact')
  call ok(jp_solution_coeffs(sol, coeffs, msg), 'jp_solution_coeffs')
  call ok(jp_solution_amplitude(sol, 1, 2, a1(2)), 'jp_solution_amplitude')
  call check(all(abs(hypot(coeffs(:, 2), coeffs(:, 3)) - a1) <= 1d-12 * maxval(a1)), 'coefficients vs amplitudes')
  call check(jp_solution_amplitude(sol, 1, 3, amp) == JPROM_INVALID_VALUE, 'output 3 of 2 is refused')
  call ok(jp_solution_convergence(sol, it, res), 'jp_solution_convergence')
  call check(it >= 0 .and. res < 1d-8, 'converged')
  call ok(jp_solution_energy(sol, energy, msg), 'jp_solution_energy')
  call check(energy(1) >= 0, 'dissipated energy >= 0')
  call ok(jp_solution_n_samples(sol, ns), 'jp_solution_n_samples')
  allocate (states(ns))
  call ok(jp_solution_contact_states(sol, 1, states, msg), 'jp_solution_contact_states')
  call check(all(states >= 0 .and. states <= 2) .and. ns > 0, 'contact states are 0, 1 or 2')
  call check(jp_solution_contact_states(sol, 2, states, msg) /= JPROM_OK .and. msg /= '', 'contact 2 of 1 is refused')
  call ok(jp_solution_save(sol, trim(dir) // '/solution.json', msg), 'jp_solution_save')
  call ok(jp_solution_load(trim(dir) // '/solution.json', sol2, msg), 'jp_solution_load')
  call ok(jp_solution_amplitude(sol2, 1, 1, amp), 'jp_solution_amplitude')
  call check(amp == a1(1), 'solution saved and loaded: same amplitude')
  s = jp_solution_free(sol2)

  ! ---- model variants: clone, save/load, excitation level, Jenkins, two-body contact ----
  call ok(jp_model_clone(model, copy, msg), 'jp_model_clone')
  call ok(jp_model_save(model, trim(dir) // '/model.json', msg), 'jp_model_save')
  call ok(jp_model_load(trim(dir) // '/model.json', loaded, msg), 'jp_model_load')
  call ok(jp_solve_point(loaded, 100.0d0, opts, sol2, msg), 'jp_solve_point (loaded model)')
  call ok(jp_solution_amplitude(sol2, 1, 1, amp), 'jp_solution_amplitude')
  call check(abs(amp - a1(1)) <= 1d-12 * a1(1), 'model saved and loaded: same solution')
  s = jp_solution_free(sol2)
  call ok(jp_set_static_force(copy, [0d0, 0d0, 0d0, 0d0, 0d0, -1d0], msg), 'jp_set_static_force')
  call ok(jp_set_harmonic_force(copy, 2, fc, zeros, msg), 'jp_set_harmonic_force')
  call ok(jp_set_excitation_level(copy, 0.25d0, msg), 'jp_set_excitation_level')
  call ok(jp_excitation_level(copy, alpha, msg), 'jp_excitation_level')
  call check(abs(alpha - 0.25d0) <= 1d-12, 'excitation level reads back')
  call ok(jp_set_dynamic_scale(copy, 2.0d0, msg), 'jp_set_dynamic_scale')
  call ok(jp_set_modal_damping(copy, 0.01d0, 100.0d0, msg), 'jp_set_modal_damping')
  call check(jp_set_modal_damping(copy, -1.0d0, 100.0d0, msg) == JPROM_INVALID_VALUE .and. msg /= '', &
             'a negative damping ratio is refused with a message')
  call ok(jp_add_jenkins(copy, 2, 1.0d4, 0.3d0, 10.0d0, message=msg), 'jp_add_jenkins (ground)')
  call ok(jp_add_jenkins(copy, 3, 1.0d4, 0.3d0, 10.0d0, dof_b=1, message=msg), 'jp_add_jenkins (two DoFs)')
  call ok(jp_model_sizes(copy, nd, nc, no, msg), 'jp_model_sizes')
  call check(nc == 3, 'a ground contact and two Jenkins elements: 3 contacts')
  s = jp_model_free(csc)
  call ok(jp_model_new(mass, stiffness, csc, msg), 'jp_model_new')
  call ok(jp_add_contact(csc, [1, 2, 3], [4, 5, 6], frame, 3.0d4, 3.0d4, 5.0d4, 0.5d0, 20.0d0, msg), 'jp_add_contact')
  call ok(jp_model_sizes(csc, nd, nc, no, msg), 'jp_model_sizes')
  call check(nc == 1, 'a two-body contact')
  call check(jp_add_jenkins(copy, 7, 1.0d4, 0.3d0, 10.0d0, message=msg) /= JPROM_OK .and. msg /= '', 'DoF 7 of 6 is refused')
  call ok(jp_model_validate(copy, msg), 'jp_model_validate')
  s = jp_model_free(copy)
  s = jp_model_free(loaded)
  s = jp_model_free(csc)

  ! ---- sweeps ----
  call ok(jp_sweep(model, opts, band, sweep, msg), 'jp_sweep')
  call ok(jp_sweep_n_points(sweep, npts), 'jp_sweep_n_points')
  call ok(jp_sweep_reached_end(sweep, reached), 'jp_sweep_reached_end')
  call ok(jp_sweep_end(sweep, reason, why), 'jp_sweep_end')
  call check(reached .and. reason == JPROM_SWEEP_REACHED_END .and. jp_sweep_end_name(reason) == 'reached_end', &
             'the sweep reached the end')
  call ok(jp_sweep_n_gaps(sweep, ngap), 'jp_sweep_n_gaps')
  call check(ngap == 0 .and. jp_sweep_gap(sweep, 1, ew, ew2, why) == JPROM_INVALID_VALUE, 'no gaps, gap 1 refused')
  ! a Duffing oscillator's hardening peak: two folds, met in order, inside the band
  call ok(jp_model_new(reshape([1.0d0], [1, 1]), reshape([1.0d0], [1, 1]), duffing, msg), 'jp_model_new')
  call ok(jp_add_polynomial_spring(duffing, 1, [0.0d0, 0.0d0, 0.5d0], message=msg), 'jp_add_polynomial_spring')
  call ok(jp_set_damping(duffing, 0.05d0, 0.0d0, msg), 'jp_set_damping')
  call ok(jp_set_first_harmonic_force(duffing, [0.3d0], [0.0d0], msg), 'jp_set_first_harmonic_force')
  call ok(jp_set_outputs(duffing, [1]), 'jp_set_outputs')
  call jp_default_options(dopts, dband)
  dopts%harmonics = 5
  dband%omega_start = 0.6d0; dband%omega_end = 2.6d0
  call ok(jp_sweep(duffing, dopts, dband, dsweep, msg), 'jp_sweep')
  call ok(jp_sweep_n_events(dsweep, nev), 'jp_sweep_n_events')
  call ok(jp_sweep_event(dsweep, 1, ekind, ew, etol, eafter, eamp), 'jp_sweep_event')
  call ok(jp_sweep_event(dsweep, 2, ekind, ew2, etol, eafter2, eamp), 'jp_sweep_event')
  call check(nev == 2 .and. ekind == JPROM_EVENT_FOLD .and. jp_event_kind_name(ekind) == 'fold' .and. ew2 < ew &
             .and. ew > 0.6d0 .and. ew < 2.6d0 .and. etol > 0 .and. etol < 1d-6 * ew2 .and. eamp > 0 &
             .and. eafter >= 1 .and. eafter2 > eafter, 'two folds of the Duffing peak, in branch order')
  call check(jp_sweep_event(dsweep, 3, ekind, ew, etol, eafter, eamp) == JPROM_INVALID_VALUE, 'event 3 of 2 refused')
  s = jp_sweep_free(dsweep)
  s = jp_model_free(duffing)
  k = npts / 2
  call ok(jp_sweep_point(sweep, k, omega, a1), 'jp_sweep_point')
  call ok(jp_sweep_solution(sweep, k, sol2, msg), 'jp_sweep_solution')
  call ok(jp_solution_omega(sol2, omega2), 'jp_solution_omega')
  call ok(jp_solution_amplitude(sol2, 1, 2, amp), 'jp_solution_amplitude')
  call check(omega2 == omega .and. amp == a1(2), 'point k copied out: same omega and amplitude')
  s = jp_solution_free(sol2)
  call ok(jp_sweep_point_energy(sweep, k, energy, msg), 'jp_sweep_point_energy')
  call ok(jp_sweep_point_convergence(sweep, k, it, res), 'jp_sweep_point_convergence')
  call check(energy(1) >= 0 .and. res < 1d-8, 'point energy and convergence')
  call check(jp_sweep_point(sweep, npts + 1, omega, a2) == JPROM_INVALID_VALUE, 'point npts + 1 is refused')
  call check(jp_sweep_point(sweep, 0, omega, a2) /= JPROM_OK, 'point 0 is refused (1-based)')
  call ok(jp_sweep_save(sweep, trim(dir) // '/sweep.json', msg), 'jp_sweep_save')
  call ok(jp_sweep_load(trim(dir) // '/sweep.json', sweep2, msg), 'jp_sweep_load')
  call ok(jp_sweep_n_points(sweep2, npts2), 'jp_sweep_n_points')
  call ok(jp_sweep_point(sweep2, k, omega2, a2), 'jp_sweep_point')
  call check(npts2 == npts .and. omega2 == omega .and. all(a2 == a1), 'sweep saved and loaded: same points')
  s = jp_sweep_free(sweep2)
  s = jp_sweep_free(sweep)

  ! ---- JP: basis of a full-order solution, save/load, reduced sweep, actual error ----
  call jp_default_jp_options(jp_opts)
  call check(jp_opts%struct_size == c_sizeof(jp_opts) .and. jp_opts%threshold == 0.05d0 .and. &
             jp_opts%slipping == JPROM_SLIPPING_NEVER .and. jp_opts%regeneration_samples == 10 .and. &
             jp_opts%screen == 1 .and. jp_opts%verify == 1 .and. jp_opts%response_output == 0, 'jp_default_jp_options')
  call ok(jp_basis_from_solution(model, sol, opts, jp_opts, 60.0d0, 160.0d0, basis, msg), 'jp_basis_from_solution')
  call ok(jp_basis_sizes(basis, sizes, hh), 'jp_basis_sizes')
  call ok(jp_basis_save(basis, trim(dir) // '/basis.json', msg), 'jp_basis_save')
  call ok(jp_basis_load(trim(dir) // '/basis.json', basis2, msg), 'jp_basis_load')
  call ok(jp_basis_sizes(basis2, sizes2, hh), 'jp_basis_sizes')
  call check(all(sizes == sizes2) .and. sizes(1) > 0, 'basis saved and loaded: same sizes')
  s = jp_basis_free(basis2)
  call ok(jp_rom_sweep(model, basis, JPROM_ROM_NLR, opts, band, rsweep, msg), 'jp_rom_sweep')
  call ok(jp_sweep_n_points(rsweep, npts), 'jp_sweep_n_points')
  k = npts / 2
  call ok(jp_sweep_point_error(rsweep, k, 1, estar), 'jp_sweep_point_error')
  call check(jp_sweep_trust(rsweep, trusted, trust_why, msg) == JPROM_INVALID_VALUE .and. msg /= '', &
             'a plain reduced sweep has no verdict')
  call ok(jp_sweep_solution(rsweep, k, rsol, msg), 'jp_sweep_solution')
  call ok(jp_solution_omega(rsol, omega), 'jp_solution_omega')
  call ok(jp_solve_point(model, omega, opts, full, msg), 'jp_solve_point')
  call ok(jp_rom_actual_error(model, basis, JPROM_ROM_NLR, opts, rsol, full, e, msg), 'jp_rom_actual_error')
  call check(all(e >= 0) .and. e(1) < 1 .and. estar >= 0, 'actual and predicted errors')
  write (*, '(a,es10.3,a,es10.3)') '# mid-band NLR point on the basis of one solution: e_1 = ', e(1), ', e*_1 = ', estar
  call check(jp_rom_actual_error(model, basis, JPROM_ROM_NLR, opts, rsol, sol, e, msg) == JPROM_INVALID_VALUE .and. &
             msg /= '', 'actual error against a solution at another omega is refused')
  s = jp_solution_free(full)
  s = jp_solution_free(rsol)
  s = jp_sweep_free(rsweep)
  s = jp_basis_free(basis)
  call ok(jp_rom_sweep_adaptive(model, JPROM_ROM_NLR, opts, band, jp_opts, asweep, abasis, msg), 'jp_rom_sweep_adaptive')
  call ok(jp_sweep_n_corrections(asweep, k), 'jp_sweep_n_corrections')
  if (k > 0) then
    call ok(jp_sweep_correction(asweep, 1, kind, value, wb, wa, sizes, msg), 'jp_sweep_correction')
    call check(kind == JPROM_CORRECTION_REPLACED .or. kind == JPROM_CORRECTION_REGENERATED .or. &
               kind == JPROM_CORRECTION_GAMMA_INCREASED, 'correction kind')
    call ok(jp_sweep_correction_swept(asweep, 1, swept, msg), 'jp_sweep_correction_swept')
  end if
  call check(jp_sweep_correction_swept(asweep, k + 1, swept, msg) == JPROM_INVALID_VALUE .and. msg /= '', &
             'correction_swept of correction n + 1 is refused')
  call check(jp_correction_kind_name(JPROM_CORRECTION_REPLACED) == 'replaced' .and. &
             jp_correction_kind_name(JPROM_CORRECTION_REGENERATED) == 'regenerated' .and. &
             jp_correction_kind_name(JPROM_CORRECTION_GAMMA_INCREASED) == 'gamma_increased' .and. &
             jp_correction_kind_name(-1) == 'unknown', 'correction kind names')
  call ok(jp_sweep_correction_end(asweep, cend, judged, msg), 'jp_sweep_correction_end')
  call check((cend == JPROM_CORRECTIONS_WITHIN_THRESHOLD .and. judged <= jp_opts%threshold) .or. &
             (cend == JPROM_CORRECTIONS_MAX_CORRECTIONS .and. judged > jp_opts%threshold) .or. &
             (cend == JPROM_CORRECTIONS_NO_PROGRESS .and. judged > jp_opts%threshold), 'correction end and judged error')
  call check(jp_correction_end_name(cend) /= 'unknown' .and. jp_correction_end_name(99) == 'unknown', 'correction end names')
  call ok(jp_sweep_static_error(asweep, w0err, msg), 'jp_sweep_static_error')
  call check(w0err >= 0.0d0, 'static contact displacement error')
  ! the verdict agrees with the judged errors of its points
  call ok(jp_sweep_trust(asweep, trusted, trust_why, msg), 'jp_sweep_trust')
  call ok(jp_sweep_n_points(asweep, na), 'jp_sweep_n_points (self-correcting)')
  judged_worst = 0
  do ip = 1, na
    call ok(jp_sweep_judged_error(asweep, ip, judged_i, msg), 'jp_sweep_judged_error')
    call check(judged_i >= 0.0d0, 'judged error >= 0')
    judged_worst = max(judged_worst, judged_i)
  end do
  call check(trusted .eqv. (judged_worst <= jp_opts%threshold .and. len_trim(trust_why) == 0), 'trusted and judged errors')
  call check(trusted .or. len_trim(trust_why) > 0, 'an untrusted sweep says why')
  call check(jp_sweep_judged_error(asweep, na + 1, judged_i, msg) == JPROM_INVALID_VALUE .and. msg /= '', &
             'judged error of point n + 1 is refused')
  call check(jp_sweep_correction(asweep, k + 1, kind, value, wb, wa, sizes, msg) == JPROM_INVALID_VALUE, &
             'correction n + 1 is refused')
  s = jp_sweep_free(asweep)
  s = jp_basis_free(abasis)

  ! ---- FE model: the two nodes plus an interior node 13 on node 12 (1-based CSC, node ids 11,
  ! 12, 13), reduced with all its interior modes (exact) vs the same 9-DoF model solved directly ----
  mass9 = 0; stiffness9 = 0
  mass9(1:6, 1:6) = mass; stiffness9(1:6, 1:6) = stiffness
  do d = 1, 3
    mass9(6 + d, 6 + d) = 1
    stiffness9(3 + d, 3 + d) = stiffness9(3 + d, 3 + d) + 5.0d3; stiffness9(6 + d, 6 + d) = 5.0d3
    stiffness9(3 + d, 6 + d) = -5.0d3; stiffness9(6 + d, 3 + d) = -5.0d3
  end do
  call ok(jp_model_new(mass9, stiffness9, copy, msg), 'jp_model_new (9 DoFs)')
  call ok(jp_add_ground_contact(copy, [4, 5, 6], frame, 3.0d4, 3.0d4, 5.0d4, 0.5d0, 20.0d0, msg), 'contact')
  call ok(jp_set_damping(copy, 0.0d0, 1.0d-4, msg), 'jp_set_damping')
  call ok(jp_set_first_harmonic_force(copy, [fc, 0d0, 0d0, 0d0], [fs, 0d0, 0d0, 0d0], msg), 'force')
  call ok(jp_set_outputs(copy, [1, 4], msg), 'jp_set_outputs')
  call ok(jp_solve_point(copy, 100.0d0, opts, sol2, msg), 'jp_solve_point (9 DoFs)')
  call ok(jp_solution_amplitude(sol2, 1, 1, a1(1)), 'jp_solution_amplitude')
  call ok(jp_solution_amplitude(sol2, 1, 2, a1(2)), 'jp_solution_amplitude')
  s = jp_solution_free(sol2)
  s = jp_model_free(copy)
  deallocate (colptr, rowind, kvals, mvals)
  call to_csc(stiffness9, colptr, rowind, kvals)
  node_rows = 0
  node_rows(1:3, 1) = [1, 2, 3]
  node_rows(1:3, 2) = [4, 5, 6]
  node_rows(1:3, 3) = [7, 8, 9]
  call ok(jp_fe_new_csc(9, colptr, rowind, kvals, [(i, i = 1, 10)], [(i, i = 1, 9)], [(1.0d0, i = 1, 9)], &
                        [11_c_int64_t, 12_c_int64_t, 13_c_int64_t], node_rows, fe, msg), 'jp_fe_new_csc')
  call ok(jp_fe_n_dof(fe, nd), 'jp_fe_n_dof')
  call check(nd == 9, 'FE model: 9 DoFs')
  call check(jp_fe_new_csc(9, colptr, rowind, kvals, [(i, i = 1, 10)], [(i, i = 1, 9)], [(1.0d0, i = 1, 9)], &
                           [11_c_int64_t, 12_c_int64_t], node_rows, reduced, msg) == JPROM_BAD_SIZE .and. msg /= '', &
             'node_rows of another size than node_ids is refused')
  call ok(jp_fe_keep_node(fe, 11_c_int64_t, msg), 'jp_fe_keep_node')
  call ok(jp_fe_add_contact(fe, 12_c_int64_t, frame, 3.0d4, 3.0d4, 5.0d4, 0.5d0, 20.0d0, msg), 'jp_fe_add_contact')
  call ok(jp_fe_add_force(fe, 11_c_int64_t, 1, [5.0d0, 0.0d0, 0.0d0], msg), 'jp_fe_add_force')
  call ok(jp_fe_add_output(fe, 11_c_int64_t, 1, msg), 'jp_fe_add_output')
  call ok(jp_fe_add_output(fe, 12_c_int64_t, 1, msg), 'jp_fe_add_output')
  call check(jp_fe_add_output(fe, 14_c_int64_t, 1, msg) /= JPROM_OK .and. msg /= '', 'unknown node 14 is refused')
  call ok(jp_fe_reduce(fe, 3, reduced, msg), 'jp_fe_reduce')
  call ok(jp_set_damping(reduced, 0.0d0, 1.0d-4, msg), 'jp_set_damping')
  call ok(jp_solve_point(reduced, 100.0d0, opts, sol2, msg), 'jp_solve_point (reduced FE model)')
  call ok(jp_solution_amplitude(sol2, 1, 1, a2(1)), 'jp_solution_amplitude')
  call ok(jp_solution_amplitude(sol2, 1, 2, a2(2)), 'jp_solution_amplitude')
  call check(all(abs(a1 - a2) <= 1d-9 * maxval(a1)), 'FE model reduced with every interior mode: the 9-DoF solution')
  s = jp_solution_free(sol2)
  s = jp_model_free(reduced)
  s = jp_fe_free(fe)

  s = jp_solution_free(sol)
  s = jp_model_free(model)
  call ok(jp_live_handle_count(handles), 'jp_live_handle_count')
  call check(handles == handles0, 'every handle freed')
  write (*, '(a)') 'all checks passed'

contains
  subroutine ok(status, what)
    integer, intent(in) :: status
    character(len=*), intent(in) :: what
    if (status /= JPROM_OK) then
      write (*, '(a,a,a,a,a)') 'FAIL ', what, ': ', jp_status_name(status), ' ' // trim(msg)
      error stop 1
    end if
  end subroutine

  subroutine check(cond, what)
    logical, intent(in) :: cond
    character(len=*), intent(in) :: what
    if (.not. cond) then
      write (*, '(a,a,a,a)') 'FAIL ', what, ': ', trim(msg)
      error stop 1
    end if
    write (*, '(a,a)') 'ok ', what
  end subroutine

  !> A dense matrix in 1-based CSC form.
  subroutine to_csc(a, colptr, rowind, values)
    real(c_double), intent(in) :: a(:, :)
    integer, allocatable, intent(out) :: colptr(:), rowind(:)
    real(c_double), allocatable, intent(out) :: values(:)
    integer :: i, j
    allocate (colptr(size(a, 2) + 1), rowind(0), values(0))
    colptr(1) = 1
    do j = 1, size(a, 2)
      do i = 1, size(a, 1)
        if (a(i, j) /= 0) then
          rowind = [rowind, i]
          values = [values, a(i, j)]
        end if
      end do
      colptr(j + 1) = size(rowind) + 1
    end do
  end subroutine
end program
