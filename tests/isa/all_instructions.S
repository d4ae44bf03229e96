# Every tpsim instruction with varied operands; assembled by clang at build time and
# disassembled by llvm-objdump, the independent oracle for test_isa's decoder and
# disassembler checks. One instruction per line (the test pairs lines with words).
# The custom extension is not in llvm and is tested separately.
add s1, a4, tp
sub s10, s10, a6
sll s11, t4, s5
slt s11, s9, s3
sltu t4, t0, t2
xor s9, s10, t6
srl gp, a4, s1
sra a2, t5, s8
or t2, s3, s4
and t2, s0, t3
mul a6, t5, ra
mulh s7, a2, a3
mulhsu s7, a3, s0
mulhu s8, a2, a0
div a6, s10, s4
divu s9, t4, a3
rem s2, s9, zero
remu a3, s11, s4
addi s6, s7, 153
slti s2, a5, 0
sltiu s7, t6, 1
xori t6, ra, -241
ori a0, gp, -2048
andi s3, t2, 0
slli ra, a1, 1
srli a3, s7, 16
srai s6, s10, 0
lb s8, 2047(s8)
lh a3, 1730(t5)
lw s4, -2048(a5)
lbu a3, 0(t1)
lhu s10, -2048(s6)
jalr ra, 1996(gp)
sb s9, 0(s1)
sh s7, 0(a7)
sw t3, -2048(a0)
flw fs5, 1(sp)
fsw fs10, 1(t1)
lui s9, 569546
auipc t6, 276287
beq s10, a4, 4094
bne t3, a3, -2922
blt a2, t1, -4096
bge s9, t4, 8
bltu a6, s9, 0
bgeu s11, a0, 4094
jal t0, -1048576
fadd.s fs8, ft5, ft4, rmm
fsub.s ft1, fa6, ft10, rne
fmul.s fs3, ft6, fa4, rup
fdiv.s fa3, ft4, ft3, rmm
fsqrt.s fs11, fs1, rup
fmadd.s ft6, ft4, fs11, ft1, rne
fmsub.s fs7, fs4, ft4, ft10, rne
fnmsub.s fa5, fa1, fa0, fa7, rtz
fnmadd.s fs3, ft1, fs10, fs5, rne
fsgnj.s ft11, fs8, fs1
fsgnjn.s fa1, ft9, ft10
fsgnjx.s fs0, ft2, fs1
fmin.s fa6, fa4, fs8
fmax.s fs7, fs4, fs10
feq.s zero, ft5, fs11
flt.s gp, ft7, fs4
fle.s s3, ft8, ft2
fcvt.w.s a3, fs3, rdn
fcvt.wu.s ra, fs2, rne
fcvt.s.w fs4, t2, rne
fcvt.s.wu ft4, a6, rtz
fmv.x.w sp, ft9
fclass.s ra, fs5
fmv.w.x fa4, s3
csrrw s8, fcsr, a6
csrrs s11, fflags, s4
csrrc a3, frm, s6
csrrs s2, cycle, s6
csrrs a3, instreth, t6
csrrw s5, mtvec, zero
csrrs a7, mhartid, a1
csrrc s3, mstatus, s9
csrrw t4, 1984, a6
csrrwi t1, frm, 8
csrrsi t1, fflags, 26
csrrci s8, mscratch, 17
csrrsi a4, mepc, 8
add s2, a3, t1
sub t0, a3, t1
sll s9, t0, t4
slt zero, a3, a7
sltu t1, s2, s8
xor t6, a5, t0
srl s9, a0, sp
sra t3, t0, s5
or a2, t5, a1
and s10, t5, t0
mul s7, s9, s3
mulh s3, t0, a7
mulhsu tp, t5, t4
mulhu s5, s5, s0
div a3, t3, s6
divu a3, t2, t0
rem a4, s2, a0
remu a2, s0, t2
addi s1, s1, -1
slti t4, s10, 2047
sltiu s4, s1, -1
xori sp, s7, -1
ori gp, t6, 414
andi a5, t3, -657
slli s9, t1, 1
srli t2, zero, 27
srai s3, s8, 0
lb t1, -1(t0)
lh s7, 0(a1)
lw t5, 1(s6)
lbu gp, 2047(ra)
lhu s7, 786(s6)
jalr a2, 1993(s5)
sb zero, 0(t5)
sh a3, 0(s9)
sw zero, 2047(t3)
flw fa3, 2047(s11)
fsw fa3, 1(s5)
lui s0, 0
auipc a4, 244785
beq s9, a4, -4096
bne s9, s2, 0
blt t4, t3, -16
bge t6, ra, 4094
bltu t0, t5, 8
bgeu t2, ra, 8
jal s5, -1048576
fadd.s ft6, fs9, fa4, dyn
fsub.s fa2, fa4, fa7, rne
fmul.s fa4, fa2, fa0, rmm
fdiv.s fa2, fs1, ft2, rne
fsqrt.s fs8, fs6, rmm
fmadd.s ft11, ft4, fs1, fa7, rdn
fmsub.s fs8, fs6, ft0, fa7, rtz
fnmsub.s fa6, fs7, fa3, fa0, dyn
fnmadd.s fa2, fa0, fa2, ft6, rne
fsgnj.s ft1, fa5, ft8
fsgnjn.s fa2, ft5, fs3
fsgnjx.s fa3, fs11, ft1
fmin.s fs8, fs1, ft0
fmax.s fs0, ft10, fs0
feq.s s4, fs11, fa6
flt.s a4, ft10, ft5
fle.s s4, fs3, ft9
fcvt.w.s s8, fa7, dyn
fcvt.wu.s a0, ft0, rup
fcvt.s.w ft6, t1, rne
fcvt.s.wu fa7, s0, rdn
fmv.x.w s9, ft4
fclass.s t3, fs5
fmv.w.x ft4, s2
csrrw s4, fcsr, a2
csrrs s7, fflags, s8
csrrc ra, frm, zero
csrrs a5, cycle, s5
csrrs a3, instreth, a7
csrrw t5, mtvec, s6
csrrs s2, mhartid, s9
csrrc s8, mstatus, s5
csrrw s1, 1984, t5
csrrwi a4, frm, 28
csrrsi a1, fflags, 7
csrrci s4, mscratch, 22
csrrsi a2, mepc, 22
add a4, s0, s9
sub t6, a5, a2
sll t5, a3, tp
slt t2, s5, t2
sltu a7, a4, s10
xor t1, a2, s0
srl t6, a1, t1
sra s4, t0, t3
or t0, t2, t1
and ra, tp, a0
mul a5, a7, t5
mulh a7, a2, s9
mulhsu a5, t3, s3
mulhu sp, s6, t5
div s0, zero, s6
divu a2, t5, tp
rem s6, tp, s2
remu a5, s7, a2
addi t4, a6, 2047
slti a0, a5, -2048
sltiu s10, t0, -1932
xori s2, s0, -1
ori ra, s2, 1
andi t0, a4, -852
slli ra, t0, 0
srli gp, a6, 8
srai s4, a1, 1
lb t1, 1(s3)
lh gp, -2048(t5)
lw a4, 2047(s8)
lbu s6, 0(s0)
lhu t2, 2047(a0)
jalr a0, 2047(a4)
sb s1, 0(s2)
sh t3, -2048(s2)
sw t0, 2047(a7)
flw fs9, 2047(zero)
fsw ft1, 0(a2)
lui sp, 102953
auipc s7, 524288
beq zero, s10, 8
bne tp, a3, -2324
blt s7, s2, -4096
bge s9, s9, -4096
bltu s11, tp, 8
bgeu t2, s10, 4094
jal ra, -10884
fadd.s ft5, fs9, ft4, rdn
fsub.s ft11, fs11, ft7, rne
fmul.s ft0, ft1, fs10, rmm
fdiv.s fa5, fs6, fs11, dyn
fsqrt.s fs7, fs5, rmm
fmadd.s fa7, ft10, fa7, fs7, rtz
fmsub.s fs0, ft4, fs0, fs5, rdn
fnmsub.s fa7, fa3, fs4, fs11, rtz
fnmadd.s fs5, fa0, ft7, fs10, rtz
fsgnj.s fa0, ft8, fs3
fsgnjn.s fs4, ft8, fs6
fsgnjx.s fs9, ft4, ft8
fmin.s ft5, ft5, fa3
fmax.s fa2, ft9, fs8
feq.s s10, fa5, ft10
flt.s s11, fs4, fs8
fle.s s7, ft0, fs5
fcvt.w.s t4, ft1, rmm
fcvt.wu.s s8, fa0, rmm
fcvt.s.w fs2, t4, rtz
fcvt.s.wu fs0, s6, rtz
fmv.x.w gp, fa1
fclass.s t6, fa2
fmv.w.x fa1, a7
csrrw s6, fcsr, ra
csrrs t2, fflags, s10
csrrc t3, frm, t4
csrrs gp, cycle, s0
csrrs a7, instreth, t2
csrrw t2, mtvec, a6
csrrs t0, mhartid, sp
csrrc a0, mstatus, t4
csrrw a7, 1984, t0
csrrwi a1, frm, 15
csrrsi sp, fflags, 7
csrrci t3, mscratch, 7
csrrsi t5, mepc, 7
fence iorw, iorw
fence r, w
fence i, o
fence.i
ecall
ebreak
mret
wfi
