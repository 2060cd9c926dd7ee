! From a CalculiX model to a self-correcting JP sweep in Fortran, as tests/c/fe_calculix.c does
! in C: contacts on the set TIP, the load at LOAD, outputs at OUT, Craig-Bampton, adaptive NLR.
! usage: fe_calculix_f90 DECK.inp kt kn mu n0 dynamic_scale omega_lo omega_hi beta cb_modes
program fe_calculix
  use, intrinsic :: iso_c_binding
  use jprom
  implicit none
  character(len=1024) :: deck, arg, msg
  real(c_double) :: v(8), frame(3, 3), omega, amps(1), e1, judged
  integer :: i, cb_modes, n_tip, n_out, n_load, n, ncorr, reason, n_fe, n_full(3), cend
  integer(c_int64_t) :: tip(256), out_nodes(16), load(1)
  type(c_ptr) :: fe, model, sweep, basis, full
  type(jprom_hbm_options) :: opts
  type(jprom_sweep_options) :: band
  type(jprom_jp_options) :: jo
  character(len=512) :: why

  call get_command_argument(1, deck)
  do i = 1, 8
    call get_command_argument(i + 1, arg)
    read (arg, *) v(i)
  end do
  call get_command_argument(10, arg)
  read (arg, *) cb_modes

  call check(jp_fe_load_calculix(deck, fe, msg), 'load')
  call check(jp_fe_node_set(fe, 'TIP', tip, n_tip, msg), 'TIP')
  call check(jp_fe_node_set(fe, 'OUT', out_nodes, n_out, msg), 'OUT')
  call check(jp_fe_node_set(fe, 'LOAD', load, n_load, msg), 'LOAD')
  ! rows t1 = y, t2 = z, n = x (the casing is beyond the tip along x)
  frame = reshape([0d0, 0d0, 1d0, 1d0, 0d0, 0d0, 0d0, 1d0, 0d0], [3, 3])
  do i = 1, n_tip
    call check(jp_fe_add_contact(fe, tip(i), frame, v(1), v(1), v(2), v(3), v(4), msg), 'contact')
  end do
  call check(jp_fe_add_force(fe, load(1), 1, [0d0, 1d0, 0d0], msg), 'force')
  do i = 1, n_out
    call check(jp_fe_add_output(fe, out_nodes(i), 2, msg), 'output')
  end do
  call check(jp_fe_reduce(fe, cb_modes, model, msg), 'reduce')
  ! the same placement without reduction: every FE DoF kept, the same contacts and outputs
  call check(jp_fe_unreduced(fe, full, msg), 'unreduced')
  call check(jp_fe_n_dof(fe, n_fe), 'FE DoFs')
  call check(jp_model_sizes(full, n_full(1), n_full(2), n_full(3), msg), 'unreduced sizes')
  if (n_full(1) /= n_fe .or. n_full(2) /= n_tip .or. n_full(3) /= n_out) then
    print '(a, 3i8, a, 3i8)', 'FAIL unreduced model sizes', n_full, ' expected', n_fe, n_tip, n_out
    stop 1
  end if
  i = jp_model_free(full)
  i = jp_fe_free(fe)
  call check(jp_set_damping(model, 0d0, v(8), msg), 'damping')
  call check(jp_set_dynamic_scale(model, v(5), msg), 'scale')

  call jp_default_options(opts, band)
  call jp_default_jp_options(jo)
  band%omega_start = v(6)
  band%omega_end = v(7)
  call check(jp_rom_sweep_adaptive(model, JPROM_ROM_NLR, opts, band, jo, sweep, basis, msg), 'adaptive sweep')
  i = jp_sweep_n_points(sweep, n)
  i = jp_sweep_n_corrections(sweep, ncorr)
  i = jp_sweep_end(sweep, reason, why)
  write (*, '(a, i0, a, i0, a, i0)') '# Fortran: ', n, ' points, ', ncorr, ' corrections, end ', reason
  call check(jp_sweep_correction_end(sweep, cend, judged, msg), 'correction end')
  write (*, '(a, i0, 1x, es26.17e3)') '# corrections end ', cend, judged
  do i = 1, n
    call check(jp_sweep_point(sweep, i, omega, amps), 'point')
    call check(jp_sweep_point_error(sweep, i, 1, e1), 'e*')
    write (*, '(3es26.17e3)') omega, amps(1), e1
  end do
  i = jp_sweep_free(sweep)
  i = jp_basis_free(basis)
  i = jp_model_free(model)
contains
  subroutine check(status, what)
    integer, intent(in) :: status
    character(len=*), intent(in) :: what
    if (status /= JPROM_OK) then
      write (*, '(a, a, a)') what, ': ', trim(msg)
      error stop 1
    end if
  end subroutine
end program
